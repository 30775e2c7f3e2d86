#include "studies/network_candidate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace tt::studies {

fitting::ModelSpec driver_network_spec(std::uint64_t seed, const std::string& sensor_method,
                                       bool use_inputs) {
  torchnet::NetworkOptions o;
  o.window_steps = 16;
  o.conv_channels = 16;
  o.gru_hidden = 16;
  o.gru_layers = 2;
  o.max_epochs = 150;
  o.patience = 20;
  o.batch_size = 64;
  o.learning_rate = 3e-3;
  o.weight_decay = kNetworkWeightDecay;
  o.time_budget_s = 300.0;
  o.seed = seed;
  o.threads = 1;
  fitting::ModelSpec spec = fitting::network_spec(o, 3600.0, sensor_method);
  spec.use_inputs = use_inputs;
  return spec;
}

fitting::Candidate linear_inputs_network(const fitting::FittedModel& chosen, std::uint64_t seed) {
  fitting::ModelSpec spec =
      driver_network_spec(seed, kLinearInputsNetworkMethod, !chosen.features.inputs.empty());
  // The chosen linear model as the network's skip: its features (lags included) and its ridge
  // strength; the network learns what it leaves.
  const auto kind = chosen.spec.kind;
  if (kind == fitting::ModelKind::least_squares || kind == fitting::ModelKind::ridge ||
      kind == fitting::ModelKind::distributed_lag) {
    spec.network.linear_skip = true;
    spec.ridge_lambda = chosen.spec.ridge_lambda;
    spec.time_constants = chosen.features.time_constants;
  }
  return {fitting::SensorSet{kLinearInputsNetworkMethod, chosen.features.sensors}, spec};
}

std::optional<fitting::Candidate> ridge_skip_network(const fitting::Evaluation& e,
                                                     std::uint64_t seed, bool use_inputs) {
  const fitting::CandidateResult* best = nullptr;
  for (const auto& c : e.selection.candidates) {
    const fitting::ModelSpec& s = e.specs[static_cast<std::size_t>(c.spec)];
    if (!c.model || s.kind != fitting::ModelKind::ridge) continue;
    const double ms = fitting::mean_square(c.validation);
    if (std::isfinite(ms) && (!best || ms < fitting::mean_square(best->validation))) best = &c;
  }
  if (!best) return std::nullopt;
  fitting::ModelSpec spec = driver_network_spec(seed, kRidgeSkipNetworkMethod, use_inputs);
  spec.network.linear_skip = true;
  spec.ridge_lambda = e.specs[static_cast<std::size_t>(best->spec)].ridge_lambda;
  return fitting::Candidate{
      fitting::SensorSet{kRidgeSkipNetworkMethod,
                         e.sensor_sets[static_cast<std::size_t>(best->sensor_set)].sensors},
      spec};
}

std::vector<fitting::SensorSet> network_sensor_sets(const placement::PlacementResult& placed,
                                                    int target) {
  const placement::Selection* best = nullptr;
  for (const auto& s : placed.targets[static_cast<std::size_t>(target)].selections)
    if (s.method == placement::Method::kGreyRelational && s.m <= 4 && (!best || s.m > best->m))
      best = &s;
  if (!best) return {};
  return {fitting::SensorSet{kNetworkSensorMethod, best->columns}};
}

std::optional<NetworkFigures> network_figures(const fitting::Evaluation& e,
                                              const std::vector<fitting::Group>& refit_groups,
                                              const std::vector<fitting::Group>& test_groups) {
  int best = -1;
  for (std::size_t i = 0; i < e.selection.candidates.size(); ++i) {
    const auto& c = e.selection.candidates[i];
    if (!c.model ||
        e.specs[static_cast<std::size_t>(c.spec)].kind != fitting::ModelKind::cnn_bigru_attention)
      continue;
    if (!std::isfinite(c.validation.sm)) continue;
    if (best < 0 ||
        c.validation.sm < e.selection.candidates[static_cast<std::size_t>(best)].validation.sm)
      best = static_cast<int>(i);
  }
  if (best < 0) return std::nullopt;
  const auto& c = e.selection.candidates[static_cast<std::size_t>(best)];
  NetworkFigures n;
  n.chosen = best == e.selection.best;
  n.validation = c.validation;
  n.model = n.chosen ? e.model
                     : fitting::fitted_model(
                           e.specs[static_cast<std::size_t>(c.spec)], refit_groups,
                           e.sensor_sets[static_cast<std::size_t>(c.sensor_set)].sensors, e.target);
  if (!test_groups.empty()) n.test = fitting::model_accuracy(n.model, test_groups);
  // One real-time prediction: the window ending at the last sample of the first test group.
  const auto& net = std::get<torchnet::Network>(n.model.body);
  const fitting::Group& g = test_groups.empty() ? refit_groups.front() : test_groups.front();
  const Eigen::MatrixXd x = fitting::feature_matrix(n.model.features, g);
  const auto window = torchnet::windows_at(x, net.options().window_steps,
                                           net.options().window_stride, {x.rows() - 1})
                          .front();
  std::vector<double> ms;
  for (int k = 0; k < 101; ++k) {
    const auto start = std::chrono::steady_clock::now();
    (void)net.window_prediction(window);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
  }
  std::nth_element(ms.begin(), ms.begin() + 50, ms.end());
  n.inference_ms = ms[50];
  return n;
}

}  // namespace tt::studies
