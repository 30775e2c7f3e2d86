// The patent's CNN-BiGRU-attention network (seed 004) as a candidate of the fit drivers: its
// spec, the sensor set it is trained on, and its own held-out figures beside the chosen model's.
#pragma once

#include <optional>
#include <vector>

#include "fitting/models.hpp"
#include "fitting/segments.hpp"
#include "fitting/selection.hpp"
#include "placement/place.hpp"

namespace tt::studies {

/// Sensor-set method of the network's inputs: the grey relational grade's best m <= 4 sensors.
inline constexpr const char* kNetworkSensorMethod = "grey_relational_network";
/// Sensor-set method of the network's other inputs: those of the linear model chosen on
/// validation for the same target (its sensors, and the speed when it reads it).
inline constexpr const char* kLinearInputsNetworkMethod = "linear_inputs_network";

/// The drivers' network: 16-entry windows spanning an hour, 16 convolution channels, a 2 x 16
/// bidirectional GRU, at most 150 epochs (patience 20) and 300 s per training, weight decay
/// kNetworkWeightDecay, seed `seed`, tried with `sensor_method`'s sets (and the operating inputs
/// when `use_inputs`).
fitting::ModelSpec driver_network_spec(std::uint64_t seed,
                                       const std::string& sensor_method = kNetworkSensorMethod,
                                       bool use_inputs = false);

/// AdamW's decoupled weight decay of the drivers' network. A few hundred windows give a few
/// optimiser steps per epoch, so it is large beside the usual 0.01.
inline constexpr double kNetworkWeightDecay = 0.3;

/// The network candidate on the inputs of the linear model chosen for a target: its sensors as a
/// set of method kLinearInputsNetworkMethod and a network spec that reads the speed when it does.
/// When that model is linear (least squares, ridge, distributed lags) it is the network's linear
/// skip (its lagged features and ridge strength): the network learns what the linear model
/// leaves, and stays that model when it cannot improve on it on the early-stopping rows.
fitting::Candidate linear_inputs_network(const fitting::FittedModel& chosen, std::uint64_t seed);

/// Sensor-set method of the network whose linear skip is static: the ridge on the temperature
/// rises (no lags) that validates best, so that the network's windows carry the dynamics.
inline constexpr const char* kRidgeSkipNetworkMethod = "ridge_skip_network";

/// The network candidate on the sensors of the ridge candidate (kind ridge) of the lowest mean
/// validation S² in `e`, with that ridge as its linear skip (the speed read beside, linearly in
/// the skip and in the windows, when `use_inputs`); nullopt when `e` holds no fitted ridge.
std::optional<fitting::Candidate> ridge_skip_network(const fitting::Evaluation& e,
                                                     std::uint64_t seed, bool use_inputs);

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

}  // namespace tt::studies
