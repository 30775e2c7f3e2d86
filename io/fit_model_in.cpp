#include "io/fit_model_in.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/errors.hpp"
#include "core/units.hpp"
#include "fitting/features.hpp"
#include "fitting/torch/network.hpp"
#include "io/fit_json_keys.hpp"

namespace tt::io {

namespace {

using fit_keys::member;
using fit_keys::names_at;
using fit_keys::number_at;
using fit_keys::Place;
using fit_keys::vector_at;
using fitting::ModelKind;
using nlohmann::json;

constexpr double um = core::kMetresPerMicrometre;

ModelKind kind_of(const std::string& name, const Place& p, const std::string& at) {
  if (const auto kind = core::value_in(fitting::kModelKindNames, name)) return *kind;
  throw core::DataError(p.at(at + "kind") + " = '" + name + "': expected " +
                        core::names_list(fitting::kModelKindNames));
}

/// The operating inputs a model reads: the key written since compensate exists, else the names
/// of its "d[...]" terms (fit.json files written before it).
std::vector<std::string> operating_inputs(const json& c, const Place& p, const std::string& at) {
  if (c.contains("operating_inputs")) return names_at(c, "operating_inputs", p, at);
  std::vector<std::string> inputs;
  if (!c.contains("terms") || !c["settings"].value("inputs", false)) return inputs;
  for (const json& t : c["terms"]) {
    const std::string name = t.value("name", std::string());
    if (name.rfind("d[", 0) == 0 && name.back() == ']')
      inputs.push_back(name.substr(2, name.size() - 3));
  }
  return inputs;
}

fitting::PprModel ppr_of(const json& c, const Place& p, const std::string& at) {
  fitting::PprModel m;
  m.center = vector_at(c, "input_center_K", p, at);
  m.scale = vector_at(c, "input_scale_K", p, at);
  m.mean = number_at(c, "mean_um", p, at) * um;
  const json& ridges = member(c, "ridge_functions", p, at);
  for (std::size_t r = 0; r < ridges.size(); ++r) {
    const std::string here = at + "ridge_functions[" + std::to_string(r) + "].";
    fitting::RidgeFunction f;
    f.direction = vector_at(ridges[r], "direction", p, here);
    f.z_low = number_at(ridges[r], "z_low", p, here);
    f.z_high = number_at(ridges[r], "z_high", p, here);
    f.polynomial = vector_at(ridges[r], "polynomial_um", p, here, um);
    if (f.direction.size() != m.center.size())
      throw core::DataError(p.at(here + "direction") + " has " +
                            std::to_string(f.direction.size()) + " entries; expected " +
                            std::to_string(m.center.size()));
    m.terms.push_back(std::move(f));
  }
  return m;
}

/// The model `c` (a model_json object) describes; `at` is its key path in messages.
/// The model's settings (`kind` read): ridge strength and time constants where the kind has them.
fitting::ModelSpec model_spec(const json& c, ModelKind kind, const Place& p,
                              const std::string& at) {
  fitting::ModelSpec spec;
  spec.kind = kind;
  const json& settings = member(c, "settings", p, at);
  spec.use_inputs = settings.value("inputs", false);
  if (kind == ModelKind::ridge || kind == ModelKind::distributed_lag)
    spec.ridge_lambda = number_at(settings, "ridge_lambda", p, at + "settings.");
  if (kind == ModelKind::distributed_lag ||
      (kind == ModelKind::cnn_bigru_attention && settings.contains("time_constants_s"))) {
    const Eigen::VectorXd taus = vector_at(settings, "time_constants_s", p, at + "settings.");
    spec.time_constants.assign(taus.data(), taus.data() + taus.size());
    for (double tau : spec.time_constants)
      if (!(tau > 0.0))
        throw core::DataError(p.at(at + "settings.time_constants_s") + " holds " +
                              std::to_string(tau) + ": every time constant must be > 0");
  }
  return spec;
}

/// The model's regressors: its sensors and operating inputs, in the order fit.json names them.
fitting::FeatureMap model_features(const json& c, const fitting::ModelSpec& spec, const Place& p,
                                   const std::string& at) {
  fitting::FeatureMap f;
  f.sensor_names = names_at(c, "sensors", p, at);
  f.input_names = operating_inputs(c, p, at);
  f.time_constants = spec.time_constants;
  for (std::size_t k = 0; k < f.sensor_names.size(); ++k) f.sensors.push_back(static_cast<int>(k));
  for (std::size_t k = 0; k < f.input_names.size(); ++k) f.inputs.push_back(static_cast<int>(k));
  return f;
}

/// A projection pursuit model whose inputs are `expected`.
/// fit.json's `inputs` of a model (projection pursuit, network) are `expected`, in order.
void require_inputs(const json& c, const std::vector<std::string>& expected, const Place& p,
                    const std::string& at) {
  const std::vector<std::string> inputs = names_at(c, "inputs", p, at);
  if (inputs != expected)
    throw core::DataError(p.at(at + "inputs") + " = " + json(inputs).dump() +
                          "; the model's sensors, inputs and time constants give " +
                          json(expected).dump());
}

fitting::PprModel checked_ppr(const json& c, const std::vector<std::string>& expected,
                              const Place& p, const std::string& at) {
  require_inputs(c, expected, p, at);
  fitting::PprModel ppr = ppr_of(c, p, at);
  if (ppr.center.size() != static_cast<Eigen::Index>(expected.size()))
    throw core::DataError(p.at(at + "input_center_K") + " has " +
                          std::to_string(ppr.center.size()) + " entries; expected " +
                          std::to_string(expected.size()));
  return ppr;
}

/// A linear model whose terms are `expected`, in order [m, m/K].
fitting::LinearFit checked_linear(const json& c, const std::vector<std::string>& expected,
                                  const Place& p, const std::string& at) {
  fitting::LinearFit fit;
  fit.intercept = number_at(c, "intercept_um", p, at) * um;
  const json& terms = member(c, "terms", p, at);
  if (!terms.is_array() || terms.size() != expected.size())
    throw core::DataError(p.at(at + "terms") + " has " + std::to_string(terms.size()) +
                          " entries; the model's sensors, inputs and time constants give " +
                          std::to_string(expected.size()) + ": " + json(expected).dump());
  fit.coefficients.resize(static_cast<Eigen::Index>(terms.size()));
  for (std::size_t k = 0; k < terms.size(); ++k) {
    const std::string here = at + "terms[" + std::to_string(k) + "].";
    const std::string name = terms[k].value("name", std::string());
    if (name != expected[k])
      throw core::DataError(p.at(here + "name") + " = '" + name + "'; expected '" + expected[k] +
                            "' (the order feature_names gives)");
    fit.coefficients(static_cast<Eigen::Index>(k)) = number_at(terms[k], "um_per_K", p, here) * um;
  }
  return fit;
}

/// `file`'s entries [m or K] against fit.json's `key` (in `scale` of them), to float32's
/// precision: a file from another fit is refused.
void require_same(const Eigen::VectorXd& file, const json& c, const std::string& key, double scale,
                  const Place& p, const std::string& at, const std::filesystem::path& path) {
  const Eigen::VectorXd given = vector_at(c, key, p, at, scale);
  const double tolerance = 1e-5 * std::max(1.0, given.cwiseAbs().maxCoeff());
  if (given.size() != file.size() || (given - file).cwiseAbs().maxCoeff() > tolerance)
    throw core::DataError(p.at(at + key) + " does not match " + path.string() +
                          ": the network file is from another fit; hint: give the fit.json it "
                          "was written with");
}

/// The network of a cnn_bigru_attention model: its TorchScript file beside fit.json, checked
/// against the shape and standardisation fit.json records; it holds the interval of the samples
/// it was trained on, which with its stride sets the time between a window's entries.
torchnet::Network checked_network(const json& c, const std::vector<std::string>& expected,
                                  fitting::FittedModel& m, const Place& p, const std::string& at,
                                  const std::filesystem::path& dir) {
  // The name fit writes; a target that is not a plain name would reach outside the directory.
  if (p.target.find('/') != std::string::npos)
    throw core::DataError(p.at(at + "kind") +
                          " = 'cnn_bigru_attention': the target's name is not "
                          "a plain name, so its network_<target>.pt cannot be beside fit.json");
  const std::filesystem::path path = dir / ("network_" + p.target + ".pt");
  if (!std::filesystem::is_regular_file(path))
    throw core::DataError(p.at(at + "kind") + " = 'cnn_bigru_attention': its weights, " +
                          path.string() +
                          ", are not there; hint: keep the network_<target>.pt files `fit` wrote "
                          "beside fit.json");
  require_inputs(c, expected, p, at);
  torchnet::Network net = torchnet::loaded_network(path);
  const int steps = static_cast<int>(number_at(c, "window_steps", p, at));
  const int stride = static_cast<int>(number_at(c, "window_stride_samples", p, at));
  if (net.inputs() != static_cast<int>(expected.size()) || net.options().window_steps != steps ||
      net.options().window_stride != stride)
    throw core::DataError(path.string() + ": a network of " + std::to_string(net.inputs()) +
                          " inputs on windows of " + std::to_string(net.options().window_steps) +
                          " entries " + std::to_string(net.options().window_stride) +
                          " samples apart; " + p.at(at) + " gives " +
                          std::to_string(expected.size()) + ", " + std::to_string(steps) + " and " +
                          std::to_string(stride) + ": the network file is from another fit");
  require_same(net.input_mean(), c, "input_mean_K", 1.0, p, at, path);
  require_same(net.output_mean(), c, "output_mean_um", um, p, at, path);
  require_same(net.output_scale(), c, "output_scale_um", um, p, at, path);
  m.output = static_cast<int>(number_at(c, "output", p, at));
  if (m.output < 0 || m.output >= net.outputs())
    throw core::DataError(p.at(at + "output") + " = " + std::to_string(m.output) + ": " +
                          path.string() + " has " + std::to_string(net.outputs()) + " outputs");
  const json& settings = c["settings"];
  m.spec.network.options = net.options();
  m.spec.network.window_span_s = settings.value("window_span_s", 0.0);
  if (!(net.options().sample_interval_s > 0.0))
    throw core::DataError(path.string() +
                          ": the network does not record the interval of the samples it was "
                          "trained on (a file written before compensate read networks), so the "
                          "time between a window's entries is not known; hint: refit");
  return net;
}

fitting::FittedModel fitted_model_of(const json& c, const Place& p, const std::string& at,
                                     const std::optional<std::filesystem::path>& network_dir) {
  const json& kind_json = member(c, "kind", p, at);
  const ModelKind kind =
      kind_of(kind_json.is_string() ? kind_json.get<std::string>() : kind_json.dump(), p, at);
  if (kind == ModelKind::cnn_bigru_attention && !network_dir)
    throw core::DataError(p.at(at + "kind") +
                          " = 'cnn_bigru_attention': the network is not evaluated here (its "
                          "weights are in network_<target>.pt, not in fit.json); hint: refit "
                          "without --network, or use the linear, ridge, distributed_lag or "
                          "projection_pursuit kinds");
  fitting::FittedModel m;
  m.target_name = p.target;
  m.spec = model_spec(c, kind, p, at);
  m.features = model_features(c, m.spec, p, at);
  const std::vector<std::string> expected = fitting::feature_names(m.features);
  if (kind == ModelKind::cnn_bigru_attention)
    m.body = checked_network(c, expected, m, p, at, *network_dir);
  else if (kind == ModelKind::projection_pursuit)
    m.body = checked_ppr(c, expected, p, at);
  else
    m.body = checked_linear(c, expected, p, at);
  return m;
}

DeployedModel deployed_model(const json& target, const Place& p,
                             const std::optional<std::filesystem::path>& network_dir) {
  const json& chosen = member(target, "chosen", p, "");
  DeployedModel d;
  d.model = fitted_model_of(member(chosen, "coefficients", p, "chosen."), p, "chosen.coefficients.",
                            network_dir);
  // The uncertainty: held-out residuals, test groups first.
  for (const char* groups : {"test", "validation"}) {
    if (!chosen.contains(groups) || !chosen[groups].contains("S_um")) continue;
    const json& s = chosen[groups]["S_um"];
    double sum = 0.0;
    int count = 0;
    for (const auto& [group, value] : s.items())
      if (value.is_number()) {
        sum += value.get<double>() * value.get<double>();
        ++count;
      }
    if (count == 0) continue;
    d.uncertainty = std::sqrt(sum / count) * um;
    d.uncertainty_groups = groups;
    return d;
  }
  throw core::DataError(p.at("chosen.test.S_um") +
                        " and chosen.validation.S_um hold no figure: no uncertainty to report");
}

}  // namespace

std::vector<DeployedModel> deployed_models(
    const json& fit, const std::string& origin,
    const std::optional<std::filesystem::path>& network_dir) {
  if (!fit.is_object() || !fit.contains("targets") || !fit["targets"].is_array() ||
      fit["targets"].empty())
    throw core::DataError(origin +
                          ": no \"targets\" list; hint: give the fit.json that `thermotwin fit` "
                          "or `thermotwin fit --data` wrote");
  std::vector<DeployedModel> models;
  for (std::size_t t = 0; t < fit["targets"].size(); ++t) {
    const json& target = fit["targets"][t];
    Place p{origin, "targets[" + std::to_string(t) + "]"};
    const json& name = member(target, "target", p, "");
    if (!name.is_string() || name.get<std::string>().empty())
      throw core::DataError(p.at("target") + " = " + name.dump() + ": expected a name");
    p.target = name.get<std::string>();
    models.push_back(deployed_model(target, p, network_dir));
    models.back().model.target = static_cast<int>(t);
  }
  return models;
}

fitting::FittedModel fitted_model_from_json(const json& coefficients, const std::string& origin,
                                            const std::string& target, const std::string& key) {
  fitting::FittedModel m =
      fitted_model_of(coefficients, Place{origin, target}, key + ".", std::nullopt);
  m.target_name = target;
  return m;
}

json read_fit_json(const std::filesystem::path& path) {
  return fit_keys::read_json(path, "a fit.json file");
}

std::vector<DeployedModel> read_deployed_models(const std::filesystem::path& path) {
  return deployed_models(read_fit_json(path), path.string(), path.parent_path());
}

}  // namespace tt::io
