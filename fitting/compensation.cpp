#include "fitting/compensation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "core/text.hpp"

namespace tt::fitting {

namespace {

int column_of(const std::string& name, const std::vector<std::string>& columns,
              const FittedModel& model, const char* what) {
  const auto it = std::find(columns.begin(), columns.end(), name);
  if (it != columns.end()) return static_cast<int>(it - columns.begin());
  const std::string listed = core::joined(columns);
  throw core::DataError("column '" + name + "' is missing: the model of target '" +
                        model.target_name + "' reads " + what + " '" + name + "'; the stream has " +
                        (listed.empty() ? "none" : listed));
}

/// The history a network's windows are read from: entries window_stride · sample_interval_s
/// apart, rows kept at least every sample interval (all of a stream at the training's rate) and
/// at most 64 per entry spacing.
std::optional<WindowHistory> network_history(const FittedModel& model) {
  const auto* network = std::get_if<torchnet::Network>(&model.body);
  if (!network) return std::nullopt;
  const auto& o = network->options();
  if (!(o.sample_interval_s > 0.0))
    throw core::DataError("the network of target '" + model.target_name +
                          "' does not say the interval of the samples it was trained on; hint: "
                          "refit it with this version");
  const double spacing = o.window_stride * o.sample_interval_s;
  return WindowHistory(o.window_steps, spacing, std::min(o.sample_interval_s, spacing / 64.0));
}

}  // namespace

WindowHistory::WindowHistory(int steps, double spacing, double keep_every)
    : steps_(steps), spacing_(spacing), keep_every_(keep_every) {
  if (steps < 1 || !(spacing > 0.0) || !(keep_every > 0.0))
    throw core::DataError("window history of " + std::to_string(steps) + " entries " +
                          std::to_string(spacing) + " s apart, kept every " +
                          std::to_string(keep_every) + " s; expected >= 1 and > 0");
}

void WindowHistory::push(double time, const Eigen::VectorXd& row) {
  latest_time_ = time;
  latest_ = row;
  // A relative margin, so that a stream at exactly keep_every keeps every row.
  if (kept_.empty() || time - kept_.back().first >= keep_every_ * (1.0 - 1e-9))
    kept_.emplace_back(time, row);
  const double oldest = time - (steps_ - 1) * spacing_;
  while (kept_.size() >= 2 && kept_[1].first <= oldest) kept_.pop_front();
}

Eigen::VectorXd WindowHistory::row_at(double time) const {
  const auto later = std::upper_bound(kept_.begin(), kept_.end(), time,
                                      [](double t, const auto& k) { return t < k.first; });
  if (later == kept_.begin()) return kept_.front().second;
  const auto& [t0, r0] = *std::prev(later);
  const double t1 = later == kept_.end() ? latest_time_ : later->first;
  const Eigen::VectorXd& r1 = later == kept_.end() ? latest_ : later->second;
  if (!(t1 > t0) || time <= t0) return r0;
  const double w = (time - t0) / (t1 - t0);
  return (1.0 - w) * r0 + w * r1;
}

Eigen::MatrixXd WindowHistory::window() const {
  if (kept_.empty()) return {};
  Eigen::MatrixXd w(steps_, latest_.size());
  for (int j = 0; j < steps_; ++j)
    w.row(j) = j + 1 == steps_ ? latest_ : row_at(latest_time_ - (steps_ - 1 - j) * spacing_);
  return w;
}

Compensator::Compensator(const std::vector<FittedModel>& models,
                         const std::vector<std::string>& columns, const Eigen::VectorXd& sigma,
                         double network_every_s)
    : network_every_s_(network_every_s) {
  if (models.empty()) throw core::DataError("compensator: no model to step");
  if (sigma.size() != 0 && sigma.size() != static_cast<Eigen::Index>(models.size()))
    throw core::DataError("compensator: " + std::to_string(sigma.size()) + " sigmas for " +
                          std::to_string(models.size()) + " models");
  if (!(network_every_s >= 0.0))
    throw core::DataError("compensator: a network evaluated every " +
                          std::to_string(network_every_s) + " s; expected >= 0");
  step_.sigma = sigma;
  for (const FittedModel& model : models) {
    windows_.push_back(network_history(model));
    evaluated_at_.push_back(-std::numeric_limits<double>::infinity());
    FittedModel bound = model;
    bound.features.sensors.clear();
    bound.features.inputs.clear();
    for (const std::string& s : model.features.sensor_names)
      bound.features.sensors.push_back(column_of(s, columns, model, "sensor"));
    for (const std::string& s : model.features.input_names)
      bound.features.inputs.push_back(column_of(s, columns, model, "input"));
    used_.insert(used_.end(), bound.features.sensors.begin(), bound.features.sensors.end());
    used_.insert(used_.end(), bound.features.inputs.begin(), bound.features.inputs.end());
    streams_.emplace_back(bound.features);
    models_.push_back(std::move(bound));
  }
  std::sort(used_.begin(), used_.end());
  used_.erase(std::unique(used_.begin(), used_.end()), used_.end());
  const auto n = static_cast<Eigen::Index>(columns.size());
  last_good_ = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  sample_ = last_good_;
  step_.predicted = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(models_.size()),
                                              std::numeric_limits<double>::quiet_NaN());
}

const LiveStep& Compensator::next(double time, const Eigen::Ref<const Eigen::VectorXd>& values) {
  if (values.size() != last_good_.size())
    throw core::DataError("compensator: a sample of " + std::to_string(values.size()) +
                          " values for " + std::to_string(last_good_.size()) + " columns");
  step_.held.clear();
  if (started_ && !(time > streams_.front().last_time())) {
    step_.status = SampleStatus::late;
    return step_;
  }
  if (!started_ && !std::isfinite(time)) {
    step_.status = SampleStatus::waiting;
    return step_;
  }
  for (int c : used_) {
    if (std::isfinite(values(c))) {
      sample_(c) = last_good_(c) = values(c);
    } else {
      sample_(c) = last_good_(c);
      step_.held.push_back(c);
    }
  }
  if (!started_ && !step_.held.empty()) {
    // The increments start from the first complete sample, as a measured group does.
    step_.status = SampleStatus::waiting;
    return step_;
  }
  started_ = true;
  for (std::size_t m = 0; m < models_.size(); ++m)
    step_.predicted(static_cast<Eigen::Index>(m)) =
        value(m, time, streams_[m].next(time, sample_, sample_));
  step_.status = step_.held.empty() ? SampleStatus::ok : SampleStatus::held;
  return step_;
}

double Compensator::value(std::size_t m, double time, const Eigen::VectorXd& row) {
  const FittedModel& model = models_[m];
  if (const auto* linear = std::get_if<LinearFit>(&model.body))
    return linear->intercept + row.dot(linear->coefficients);
  if (const auto* ppr = std::get_if<PprModel>(&model.body))
    return ppr_prediction(*ppr, row.transpose())(0);
  WindowHistory& history = *windows_[m];
  history.push(time, row);
  const auto k = static_cast<Eigen::Index>(m);
  // Once per period: a network's evaluation costs what thousands of samples' parsing does.
  if (time - evaluated_at_[m] < network_every_s_ * (1.0 - 1e-9)) return step_.predicted(k);
  evaluated_at_[m] = time;
  return std::get<torchnet::Network>(model.body).window_prediction(history.window())(model.output);
}

}  // namespace tt::fitting
