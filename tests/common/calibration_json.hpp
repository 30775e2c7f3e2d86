// Reading calibration.json (io/calibration_model_out) in tests.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace tt::test {

/// An effect's `location.centre_m` (a heat input's place) [m].
inline Eigen::Vector3d effect_centre_m(const nlohmann::json& effect) {
  const auto& c = effect.at("location").at("centre_m");
  return {c.at(0).get<double>(), c.at(1).get<double>(), c.at(2).get<double>()};
}

}  // namespace tt::test
