// A small fit.json for the CNC export's tests: a TCP dz model and an X axis of five points whose
// linear models give an exact cubic, written with io::model_json as `thermotwin fit` writes them.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fitting/models.hpp"
#include "io/fitting_out.hpp"

namespace tt::test {

using fitting::FittedModel;
using fitting::LinearFit;
using fitting::ModelKind;
using nlohmann::json;
constexpr double um = 1e-6;

inline FittedModel linear_model(const std::string& target, const std::vector<std::string>& sensors,
                                double intercept, const std::vector<double>& coefficients) {
  FittedModel m;
  m.target_name = target;
  m.spec.kind = ModelKind::least_squares;
  m.features.sensor_names = sensors;
  for (std::size_t k = 0; k < sensors.size(); ++k)
    m.features.sensors.push_back(static_cast<int>(k));
  LinearFit fit;
  fit.intercept = intercept;
  fit.coefficients = Eigen::Map<const Eigen::VectorXd>(
      coefficients.data(), static_cast<Eigen::Index>(coefficients.size()));
  m.body = fit;
  return m;
}

/// A fit.json with a TCP dz model and an X axis of 5 points whose models give dx = p^3 per K of
/// a and dy = 2 µm per K of b, dz = 0.
inline json fit_document() {
  const std::vector<double> positions{-1.0, -0.5, 0.0, 0.5, 1.0};
  json axis_targets = json::object();
  std::vector<std::string> points;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const std::string id = "A0" + std::to_string(i + 1);
    points.push_back(id);
    const double p = positions[i];
    axis_targets[id + "_dx"]["coefficients"] =
        tt::io::model_json(linear_model(id + "_dx", {"a"}, 0.0, {p * p * p * um}));
    axis_targets[id + "_dy"]["coefficients"] =
        tt::io::model_json(linear_model(id + "_dy", {"b"}, 0.0, {2 * um}));
    axis_targets[id + "_dz"]["coefficients"] =
        tt::io::model_json(linear_model(id + "_dz", {"a"}, 0.0, {0.0}));
  }
  json chosen{{"coefficients", tt::io::model_json(linear_model("dz", {"b"}, 0.0, {-4 * um}))},
              {"test", {{"S_um", {{"g", 0.5}}}}}};
  return json{{"targets", json::array({{{"target", "dz"}, {"chosen", chosen}}})},
              {"axis",
               {{"feed_axis", {{"name", "X"}, {"direction", "x"}}},
                {"points", points},
                {"positions_m", positions},
                {"degree", 3},
                {"targets", axis_targets}}}};
}

}  // namespace tt::test
