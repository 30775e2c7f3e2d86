// A fitted model as compensate reads it: fit.json's form of its chosen model (io::model_json),
// and a group's samples as a stream's columns and values (sensors, then inputs).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fitting/group.hpp"
#include "fitting/models.hpp"
#include "io/fitting_out.hpp"

namespace tt::fitting::test {

/// fit.json's form of one target's chosen model, with a test figure (S 0.3 and 0.4 µm).
inline nlohmann::json fit_doc(const FittedModel& model) {
  nlohmann::json chosen{{"coefficients", io::model_json(model)},
                        {"test", {{"S_um", {{"a", 0.3}, {"b", 0.4}}}}}};
  return nlohmann::json{
      {"format", "thermotwin-fit/1"},
      {"targets", nlohmann::json::array({{{"target", model.target_name}, {"chosen", chosen}}})}};
}

/// The group's columns as compensate's stream has them: sensors, then inputs.
inline std::vector<std::string> columns_of(const Group& g) {
  std::vector<std::string> c = g.sensor_names;
  c.insert(c.end(), g.input_names.begin(), g.input_names.end());
  return c;
}

/// Sample i of the group in columns_of's order.
inline Eigen::VectorXd sample_of(const Group& g, Eigen::Index i) {
  Eigen::VectorXd v(g.temperature.cols() + g.inputs.cols());
  v << g.temperature.row(i).transpose(), g.inputs.row(i).transpose();
  return v;
}

}  // namespace tt::fitting::test
