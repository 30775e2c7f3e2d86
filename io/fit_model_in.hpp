// The chosen model of each target read back from a fit.json that `thermotwin fit` or
// `thermotwin fit --data` wrote (io/fitting_out.hpp's model_json), as a typed FittedModel that
// fitting::predicted_error and fitting::Compensator evaluate. Linear kinds and projection pursuit
// are read from fit.json; the network kind from its TorchScript file beside it
// (network_<target>.pt), checked against what fit.json records of it.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fitting/models.hpp"

namespace tt::io {

/// One target's model as compensate runs it.
struct DeployedModel {
  /// features.sensors and features.inputs index features.sensor_names and features.input_names
  /// (0, 1, ...): bind them to a stream's columns by name before evaluating
  fitting::FittedModel model;
  /// 1-σ of the predicted error [m]: the root mean square of the per-group residual standard
  /// deviations S (DB3401/T 326-2024 formula 5) of the chosen model on its test groups, or on its
  /// validation groups when fit.json has no test figure
  double uncertainty = 0.0;
  /// "test" or "validation": which groups uncertainty comes from
  std::string uncertainty_groups;
};

/// The chosen model of every target of a parsed fit.json; `origin` names the file in messages;
/// network_dir: where a network's TorchScript file is (nullopt: a network is refused). Throws
/// DataError naming the file, the target and the key for a missing or malformed key, terms that do
/// not match the model's sensors, inputs and time constants, or a network whose file is missing
/// or from another fit.
std::vector<DeployedModel> deployed_models(
    const nlohmann::json& fit, const std::string& origin,
    const std::optional<std::filesystem::path>& network_dir = std::nullopt);

/// The model one model_json object describes (e.g. fit.json's axis.targets.<name>.coefficients),
/// as deployed_models reads a target's chosen.coefficients; `origin`, `target` and `key` (the
/// object's key path) name it in messages. Throws DataError as deployed_models does.
fitting::FittedModel fitted_model_from_json(const nlohmann::json& coefficients,
                                            const std::string& origin, const std::string& target,
                                            const std::string& key);

/// The parsed fit.json at `path`: IoError when it cannot be read, DataError when it is not JSON.
nlohmann::json read_fit_json(const std::filesystem::path& path);

/// deployed_models of the file at `path`, its networks beside it; IoError when it cannot be read,
/// DataError when it is not JSON.
std::vector<DeployedModel> read_deployed_models(const std::filesystem::path& path);

}  // namespace tt::io
