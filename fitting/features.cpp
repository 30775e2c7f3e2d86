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
    y(i) = low_pass_step(y(i - 1), u(i - 1), u(i), h, tau, std::exp(-h / tau));
  }
  return y;
}

FeatureStream::FeatureStream(const FeatureMap& map) : map_(map) {
  for (double tau : map_.time_constants)
    if (!(tau > 0.0))
      throw core::DataError("low-pass time constant = " + std::to_string(tau) + " s: must be > 0");
  const Eigen::Index k = static_cast<Eigen::Index>(map_.sensors.size() + map_.inputs.size());
  reference_.setZero(k);
  increments_.setZero(k);
  previous_.setZero(k);
  features_.setZero(k * (1 + static_cast<Eigen::Index>(map_.time_constants.size())));
}

const Eigen::VectorXd& FeatureStream::next(double time,
                                           const Eigen::Ref<const Eigen::VectorXd>& temperature,
                                           const Eigen::Ref<const Eigen::VectorXd>& inputs) {
  const Eigen::Index s = static_cast<Eigen::Index>(map_.sensors.size());
  const Eigen::Index k = increments_.size();
  if (!started_) {
    for (Eigen::Index j = 0; j < s; ++j)
      reference_(j) = temperature(map_.sensors[static_cast<std::size_t>(j)]);
    for (Eigen::Index j = s; j < k; ++j)
      reference_(j) = inputs(map_.inputs[static_cast<std::size_t>(j - s)]);
    started_ = true;
    last_time_ = time;
    // y(time_0) = u_0 = 0: every filtered increment starts at zero, like the increments.
    features_.setZero();
    increments_.setZero();
    return features_;
  }
  const double h = time - last_time_;
  if (!(h > 0.0))
    throw core::DataError("feature stream: time " + std::to_string(time) +
                          " s does not exceed the previous sample's " + std::to_string(last_time_) +
                          " s");
  previous_ = increments_;
  for (Eigen::Index j = 0; j < s; ++j)
    increments_(j) = temperature(map_.sensors[static_cast<std::size_t>(j)]) - reference_(j);
  for (Eigen::Index j = s; j < k; ++j)
    increments_(j) = inputs(map_.inputs[static_cast<std::size_t>(j - s)]) - reference_(j);
  features_.head(k) = increments_;
  for (std::size_t t = 0; t < map_.time_constants.size(); ++t) {
    const double tau = map_.time_constants[t];
    const double decay = std::exp(-h / tau);
    auto filtered = features_.segment((static_cast<Eigen::Index>(t) + 1) * k, k);
    for (Eigen::Index j = 0; j < k; ++j)
      filtered(j) = low_pass_step(filtered(j), previous_(j), increments_(j), h, tau, decay);
  }
  last_time_ = time;
  return features_;
}

Eigen::MatrixXd feature_matrix(const FeatureMap& map, const Group& group) {
  for (int s : map.sensors)
    if (s < 0 || s >= group.temperature.cols())
      throw core::DataError("sensor column " + std::to_string(s) + " in group '" + group.name +
                            "'; expected a column in [0, " +
                            std::to_string(group.temperature.cols()) + ")");
  for (int c : map.inputs)
    if (c < 0 || c >= group.inputs.cols())
      throw core::DataError("input column " + std::to_string(c) + " in group '" + group.name +
                            "'; expected a column in [0, " + std::to_string(group.inputs.cols()) +
                            ")");
  const Eigen::Index n = group.time.size();
  if (group.temperature.rows() != n || (!map.inputs.empty() && group.inputs.rows() != n))
    throw core::DataError("group '" + group.name + "': " + std::to_string(n) + " times but " +
                          std::to_string(group.temperature.rows()) + " temperature rows");
  // One implementation: the rows are the stream's, sample by sample.
  FeatureStream stream(map);
  const Eigen::Index k = static_cast<Eigen::Index>(map.sensors.size() + map.inputs.size());
  Eigen::MatrixXd features(n, k * (1 + static_cast<Eigen::Index>(map.time_constants.size())));
  const Eigen::VectorXd none(0);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::VectorXd temperature = group.temperature.row(i).transpose();
    features.row(i) = map.inputs.empty()
                          ? stream.next(group.time(i), temperature, none).transpose()
                          : stream
                                .next(group.time(i), temperature,
                                      Eigen::VectorXd(group.inputs.row(i).transpose()))
                                .transpose();
  }
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
