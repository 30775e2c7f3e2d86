// The patent's CNN-BiGRU-attention network (seed 004) as a candidate of the fit drivers: its
// spec, the sensor set it is trained on, and its own held-out figures beside the chosen model's.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "fitting/models.hpp"
#include "fitting/selection.hpp"
#include "placement/place.hpp"

namespace tt::app {

/// Sensor-set method of the network's inputs: the grey relational grade's best m <= 4 sensors.
inline constexpr const char* kNetworkSensorMethod = "grey_relational_network";

/// The drivers' network: 16-entry windows spanning an hour, 16 convolution channels, a 2 x 16
/// bidirectional GRU, at most 150 epochs (patience 20) and 300 s per training, seed `seed`.
fitting::ModelSpec driver_network_spec(std::uint64_t seed);

/// The grey relational placement's largest set of at most 4 sensors for `target`, renamed
/// kNetworkSensorMethod; empty when placement ran no grey relational ranking.
std::vector<fitting::SensorSet> network_sensor_sets(const placement::PlacementResult& placed,
                                                    int target);

/// The network's own figures on one target: the network candidate with the smallest validation
/// S_M (the chosen model when it is the network, else refitted on `refit_groups`), tested on
/// `test_groups`; its training report and the median time of one real-time window prediction.
struct NetworkFigures {
  fitting::FittedModel model;
  fitting::Accuracy validation;
  fitting::Accuracy test;
  bool chosen = false;
  double inference_ms = 0.0;
};

/// Absent (nullopt) when the evaluation holds no successful network candidate.
std::optional<NetworkFigures> network_figures(const fitting::Evaluation& e,
                                              const std::vector<fitting::Group>& refit_groups,
                                              const std::vector<fitting::Group>& test_groups);

/// For fit.json's summary: validation and test S_M, S_σ, training and inference figures [µm, s].
nlohmann::json network_json(const NetworkFigures& n);

}  // namespace tt::app
