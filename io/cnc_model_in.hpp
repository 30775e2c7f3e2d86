// The model a CNC export approximates (fitting::CncModel), read from the fit.json that
// `thermotwin fit` writes: the TCP targets dx, dy and dz (the position-independent drift) and, for
// a case with a feed axis, the axis points' models and the axis polynomial they give (the
// polynomial `fit` reports, solvers::axis_polynomial of their coefficients).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fitting/cnc_export.hpp"

namespace tt::io {

struct CncModelFile {
  fitting::CncModel model;
  /// TCP targets that are not a direction (e.g. tilts, dx_z1): no controller axis takes them
  std::vector<std::string> ignored_targets;
  /// names of the models read: the TCP targets, then "<point>_<direction>" of the axis points
  std::vector<std::string> targets;
};

/// From a parsed fit.json; `origin` names the file in messages. Throws DataError naming the file
/// and key for a missing or malformed key (e.g. an axis section written before fit.json kept the
/// axis models' coefficients), a model that is not linear in its regressors, or a file with
/// neither a TCP direction target nor an axis.
CncModelFile cnc_model(const nlohmann::json& fit, const std::string& origin);

/// cnc_model of the file at `path` (IoError when it cannot be read, DataError when not JSON).
CncModelFile read_cnc_model(const std::filesystem::path& path);

/// Sensor samples of CSV files (time_s, sensor ids; a "_degC" suffix is dropped) as the model's
/// basis states, each file from its own first sample (fitting::basis_states).
struct StateSamples {
  Eigen::MatrixXd states;              /// #samples x #basis, the files' samples in their order
  std::vector<Eigen::Index> per_file;  /// #files: how many samples each gave
};

/// Throws IoError when a file cannot be read, DataError naming the file (and line) when it is
/// empty, has no sample, a line of the wrong width or lacks a column the basis reads.
StateSamples read_state_samples(const fitting::CncModel& model,
                                const std::vector<std::filesystem::path>& paths);

}  // namespace tt::io
