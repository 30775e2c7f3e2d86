#include "fitting/features.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "core/errors.hpp"

namespace tt::fitting {

Eigen::VectorXd low_pass(const Eigen::VectorXd& time, const Eigen::VectorXd& u, double tau) {
  if (!(tau > 0.0))
    throw core::DataError("low-pass time constant = " + std::to_string(tau) + " s: must be > 0");
  if (time.size() != u.size())
    throw core::DataError("low_pass: " + std::to_string(time.size()) + " times but " +
                          std::to_string(u.size()) + " values");
  Eigen::VectorXd y(u.size());
  if (u.size() == 0) return y;
  y(0) = u(0);
  for (Eigen::Index i = 1; i < u.size(); ++i) {
    const double h = time(i) - time(i - 1);
    const double decay = std::exp(-h / tau);
    const double slope = (u(i) - u(i - 1)) / h;
    // e = y − u obeys τe' = −e − τu' with u' constant over the interval.
    y(i) = u(i) + (y(i - 1) - u(i - 1)) * decay - tau * slope * (1.0 - decay);
  }
  return y;
}

Eigen::MatrixXd feature_matrix(const FeatureMap& map, const Group& group) {
  const Eigen::MatrixXd temperatures = temperature_increments(group, map.sensors);
  const Eigen::Index n = temperatures.rows();
  Eigen::MatrixXd increments(n, temperatures.cols() + static_cast<Eigen::Index>(map.inputs.size()));
  increments.leftCols(temperatures.cols()) = temperatures;
  for (std::size_t k = 0; k < map.inputs.size(); ++k) {
    const int c = map.inputs[k];
    if (c < 0 || c >= group.inputs.cols())
      throw core::DataError("input column " + std::to_string(c) + " in group '" + group.name +
                            "'; expected a column in [0, " + std::to_string(group.inputs.cols()) +
                            ")");
    increments.col(temperatures.cols() + static_cast<Eigen::Index>(k)) =
        group.inputs.col(c).array() - group.inputs(0, c);
  }
  const Eigen::Index k = increments.cols();
  const Eigen::Index blocks = 1 + static_cast<Eigen::Index>(map.time_constants.size());
  Eigen::MatrixXd features(n, k * blocks);
  features.leftCols(k) = increments;
  for (std::size_t t = 0; t < map.time_constants.size(); ++t)
    for (Eigen::Index j = 0; j < k; ++j)
      features.col((static_cast<Eigen::Index>(t) + 1) * k + j) =
          low_pass(group.time, increments.col(j), map.time_constants[t]);
  return features;
}

std::vector<std::string> feature_names(const FeatureMap& map) {
  std::vector<std::string> base;
  for (const std::string& s : map.sensor_names) base.push_back("dT[" + s + "]");
  for (const std::string& s : map.input_names) base.push_back("d[" + s + "]");
  std::vector<std::string> names = base;
  for (double tau : map.time_constants) {
    std::ostringstream prefix;
    prefix << "lp" << tau << "s(";
    for (const std::string& b : base) names.push_back(prefix.str() + b + ")");
  }
  return names;
}

StackedRows stacked_rows(const FeatureMap& map, const std::vector<Group>& groups, int target) {
  Eigen::Index rows = 0;
  for (const Group& g : groups) rows += g.time.size();
  const Eigen::Index cols = static_cast<Eigen::Index>((map.sensors.size() + map.inputs.size()) *
                                                      (1 + map.time_constants.size()));
  StackedRows stacked{Eigen::MatrixXd(rows, cols), Eigen::VectorXd(rows)};
  Eigen::Index row = 0;
  for (const Group& g : groups) {
    if (target < 0 || target >= g.error.cols())
      throw core::DataError("target " + std::to_string(target) + " in group '" + g.name +
                            "'; expected an index in [0, " + std::to_string(g.error.cols()) + ")");
    const Eigen::Index n = g.time.size();
    stacked.features.middleRows(row, n) = feature_matrix(map, g);
    stacked.error.segment(row, n) = g.error.col(target);
    row += n;
  }
  return stacked;
}

}  // namespace tt::fitting
