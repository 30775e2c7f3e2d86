#include "solvers/observer_live.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "core/text.hpp"
#include "solvers/loads.hpp"

namespace tt::solvers {

namespace {

int column_of(const std::string& name, const std::vector<std::string>& columns, const char* what) {
  const auto it = std::find(columns.begin(), columns.end(), name);
  if (it != columns.end()) return static_cast<int>(it - columns.begin());
  const std::string listed = core::joined(columns);
  throw core::DataError("column '" + name + "' is missing: the observer reads " + what + " '" +
                        name + "'; the stream has " + (listed.empty() ? "none" : listed));
}

}  // namespace

LiveObserver::LiveObserver(const ReducedThermalSystem& system, const core::CaseSpec& declared,
                           const ObserverSetup& setup, const std::vector<std::string>& sensors,
                           const std::vector<std::string>& columns, const std::string& speed_column,
                           const LiveOptions& options)
    : spec_(std::make_unique<core::CaseSpec>(declared)),
      target_names_(setup.target_names),
      every_s_(options.filter_every_s),
      from_first_(options.from_first_sample) {
  const double drift_every_s = options.drift_every_s;
  if (!(every_s_ >= 0) || !std::isfinite(every_s_))
    throw core::SolverError("live observer: a filter period of " + std::to_string(every_s_) +
                            " s; expected a finite number >= 0");
  if (static_cast<Eigen::Index>(sensors.size()) != setup.sensor_rows.rows())
    throw core::SolverError("live observer: " + std::to_string(sensors.size()) +
                            " sensor ids for " + std::to_string(setup.sensor_rows.rows()) +
                            " sensor rows");
  for (const std::string& s : sensors) sensor_columns_.push_back(column_of(s, columns, "sensor"));
  speed_column_ = column_of(speed_column, columns, "the spindle speed");
  spec_->duty_cycle.segments.clear();
  spec_->duty_cycle.end = 0;
  spec_->duty_cycle.csv.clear();
  filter_ = std::make_unique<KalmanObserver>(system, *spec_,
                                             drift_every_s > 0 ? probed_setup(setup) : setup);
  for (const std::string& t : target_names_) {
    const auto it = std::find(columns.begin(), columns.end(), t);
    drift_columns_.push_back(
        it == columns.end() || !(drift_every_s > 0) ? -1 : static_cast<int>(it - columns.begin()));
  }
  if (drift_every_s > 0) {
    if (std::all_of(drift_columns_.begin(), drift_columns_.end(), [](int c) { return c < 0; }))
      throw core::DataError(
          "drift readings asked for, but no column is named after a target of the observer (dx, "
          "dy, dz, <axis point>_dy, ...)");
    cycle_ = std::make_unique<ProbeCycle>(drift_every_s);
    drift_test_ = std::make_unique<DriftReadingTest>(system, *spec_, setup);
  }
  readings_.resize(static_cast<Eigen::Index>(sensors.size()));
  sum_ = Eigen::VectorXd::Zero(readings_.size());
  count_ = Eigen::VectorXi::Zero(readings_.size());
  const auto nt = static_cast<Eigen::Index>(target_names_.size());
  step_.predicted = Eigen::VectorXd::Constant(nt, std::numeric_limits<double>::quiet_NaN());
  step_.sigma = step_.predicted;
}

LiveObserver::~LiveObserver() = default;

const core::LiveStep& LiveObserver::next(double stream_time,
                                         const Eigen::Ref<const Eigen::VectorXd>& values) {
  step_.held.clear();
  double time = stream_time - origin_;  // the model's time (the origin is set at the first sample)
  if (!std::isfinite(time) || (started_ && !(time > last_time_)) ||
      (!started_ && !from_first_ && time < 0)) {
    step_.status = started_ ? core::SampleStatus::late : core::SampleStatus::waiting;
    return step_;
  }
  const double speed = values(speed_column_);
  if (!started_ && !std::isfinite(speed)) {
    step_.held.push_back(speed_column_);
    step_.status = core::SampleStatus::waiting;
    return step_;
  }
  if (!started_) {
    start_at(stream_time);
    time = stream_time - origin_;
  }
  // The period so far: the speed held since the last sample, then this sample's readings.
  if (started_) speed_integral_ += held_speed_ * (time - last_time_);
  if (std::isfinite(speed))
    held_speed_ = std::max(speed, 0.0);
  else
    step_.held.push_back(speed_column_);
  for (std::size_t k = 0; k < sensor_columns_.size(); ++k) {
    const double v = values(sensor_columns_[k]);
    const auto i = static_cast<Eigen::Index>(k);
    if (std::isfinite(v)) {
      sum_(i) += v;
      ++count_(i);
    } else {
      step_.held.push_back(sensor_columns_[k]);
    }
  }
  std::sort(step_.held.begin(), step_.held.end());
  const bool drift_due = cycle_ && cycle_->due(time);
  if (!started_ || drift_due || time - assimilated_time_ >= every_s_ * (1 - 1e-9))
    assimilate(time, values, drift_due);
  started_ = true;
  last_time_ = time;
  step_.status = step_.held.empty() ? core::SampleStatus::ok : core::SampleStatus::held;
  return step_;
}

void LiveObserver::start_at(double time) {
  origin_ = from_first_ ? time : 0;
  check_first_sample_time(time - origin_, spec_->thermal.step);
}

void LiveObserver::assimilate(double time, const Eigen::Ref<const Eigen::VectorXd>& values,
                              bool drift_due) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Eigen::Index k = 0; k < readings_.size(); ++k)
    readings_(k) = count_(k) > 0 ? sum_(k) / count_(k) : nan;
  // The speed over the period is its time mean: the duty cycle grows by one segment at most per
  // period, however often a noisy speed changes. The first sample's speed holds from 0.
  if (started_)
    extend_duty_cycle(spec_->duty_cycle, assimilated_time_,
                      speed_integral_ / (time - assimilated_time_));
  else
    extend_duty_cycle(spec_->duty_cycle, time, held_speed_);
  spec_->duty_cycle.end = time;
  Eigen::VectorXd drift;  // a probe cycle's reading when one is due (an empty cell: none)
  if (drift_due) {
    drift = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(drift_columns_.size()), nan);
    for (std::size_t t = 0; t < drift_columns_.size(); ++t)
      if (drift_columns_[t] >= 0) drift(static_cast<Eigen::Index>(t)) = values(drift_columns_[t]);
  }
  const ObserverEstimate e = filter_->assimilate(time, readings_, drift);
  if (drift_test_) drift_raised_ |= !std::isnan(drift_test_->add(time, readings_, drift));
  step_.predicted = e.drift;
  step_.sigma = e.drift_sigma;
  step_.recalibrate = e.recalibrate || drift_raised_;
  // Faults are only ever added: map the new ones to their columns.
  const std::vector<HeldSensor>& faults = filter_->sensor_faults();
  for (std::size_t k = step_.faulty.size(); k < faults.size(); ++k)
    step_.faulty.push_back(sensor_columns_[static_cast<std::size_t>(faults[k].sensor)]);
  sum_.setZero();
  count_.setZero();
  speed_integral_ = 0;
  assimilated_time_ = time;
  ++assimilations_;
}

}  // namespace tt::solvers
