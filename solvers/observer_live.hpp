// The physics observer on a stream of samples (thermotwin compensate --rom): the stream's header
// bound by name to the observer's sensors and the spindle speed, the duty cycle extended sample by
// sample (the speed read at a sample holds to the next one, as calibration::case_for_run reads a
// recorded run: solvers::extend_duty_cycle), and one KalmanObserver::assimilate per filter period:
// the samples of a period are one reading, their mean, at its last sample's time, and the speed
// over it is their held speeds' time mean. A period holds one sample where samples come at least
// a period apart, so a recorded run streamed through it gives what solvers::observe gives on the
// whole run; a 1 kHz stream costs one covariance step per period, not per sample.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "core/live_step.hpp"
#include "solvers/observer.hpp"

namespace tt::solvers {

/// How a LiveObserver reads its stream beside the filter's own setup.
struct LiveOptions {
  /// > 0: the columns named after the setup's targets (in m) are read as drift readings on a
  /// probe cycle of this period [s] (ProbeCycle), tested as observe tests them (DriftReadingTest)
  double drift_every_s = 0;
  /// the filter period [s]: a sample at least this long after the last assimilation (or with a
  /// drift reading due) is assimilated, with the mean of the readings since (each sensor's mean
  /// is one reading of its sigma); 0: every sample
  double filter_every_s = 0;
  /// the first sample read is t = 0 of the model (a cold start there), whatever its time_s says;
  /// false: time_s is the time since the model's t = 0, as a recorded run's is
  bool from_first_sample = false;
};

class LiveObserver {
 public:
  /// `declared`: the case (sinks, sources, films, feed axis, initial temperature); its duty cycle
  /// is the stream's. `sensors`: the setup's sensors (ids), in its order; columns: the stream's
  /// columns after time_s. Throws DataError naming the first column it reads (a sensor, or
  /// `speed_column`) that `columns` lacks, and the columns the stream has.
  /// With drift readings (options.drift_every_s > 0), throws DataError when no column is named
  /// after a target.
  LiveObserver(const ReducedThermalSystem& system, const core::CaseSpec& declared,
               const ObserverSetup& setup, const std::vector<std::string>& sensors,
               const std::vector<std::string>& columns, const std::string& speed_column,
               const LiveOptions& options = {});
  ~LiveObserver();
  LiveObserver(const LiveObserver&) = delete;
  LiveObserver& operator=(const LiveObserver&) = delete;

  /// The observer on the next sample: time [s] and one value per column (sensors [K], speed
  /// [rpm]), NaN where missing. `late` for a time not after the last sample used; `waiting` until
  /// a speed has been read; `held` with the columns whose readings were missing (left out of the
  /// period's mean, the speed held). Predicted drift and sigma per target [m] (the setup's
  /// targets); recalibrate once the observer raised it; faulty: the columns of the sensors
  /// whose offset test raised a fault (HeldBeyondMonitor); between assimilations, the last
  /// assimilation's. Throws DataError when the first sample is so late that the model would march
  /// more than core::limits::kTimeSteps steps to it (a clock's time, not a run's: read it with
  /// from_first_sample).
  const core::LiveStep& next(double time, const Eigen::Ref<const Eigen::VectorXd>& values);

  const std::vector<std::string>& target_names() const { return target_names_; }
  /// The stream's columns of the setup's sensors, in its order.
  const std::vector<int>& sensor_columns() const { return sensor_columns_; }
  /// Per target, the stream's column of its drift readings (-1: none; all -1 without a cycle).
  const std::vector<int>& drift_columns() const { return drift_columns_; }
  /// The assimilations so far (filter periods).
  long long assimilations() const { return assimilations_; }

 private:
  std::unique_ptr<core::CaseSpec> spec_;  /// the duty cycle read so far; the filter refers to it
  std::unique_ptr<KalmanObserver> filter_;
  std::unique_ptr<ProbeCycle> cycle_;             /// with drift readings
  std::unique_ptr<DriftReadingTest> drift_test_;  /// with drift readings
  bool drift_raised_ = false;
  std::vector<int> sensor_columns_, drift_columns_;
  int speed_column_ = -1;
  std::vector<std::string> target_names_;
  /// The model's origin at the first sample read (its stream time): that time, or 0.
  void start_at(double time);
  void assimilate(double time, const Eigen::Ref<const Eigen::VectorXd>& values, bool drift_due);

  double every_s_ = 0;
  /// the period so far: per sensor the sum and count of its readings, and the time integral of
  /// the speed held since the last assimilation [rpm s]
  Eigen::VectorXd sum_;
  Eigen::VectorXi count_;
  double speed_integral_ = 0;
  double held_speed_ = 0;  /// the last speed read, >= 0 [rpm]
  Eigen::VectorXd readings_;
  core::LiveStep step_;
  double last_time_ = 0, assimilated_time_ = 0;  /// the model's times [s]
  bool from_first_ = false;
  double origin_ = 0;  /// the stream's time of the model's t = 0 [s]
  long long assimilations_ = 0;
  bool started_ = false;
};

}  // namespace tt::solvers
