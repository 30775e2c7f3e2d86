// Live compensation: fitted models evaluated one sample at a time as a machine's sensors are read,
// giving exactly what predicted_error gives on the same samples taken as a group. A reading that
// is missing holds the sensor's last good value; a sample whose time does not advance is skipped.
// A network reads a window of past samples at fixed times before the current one (what
// predicted_error's rows before it are on a stream sampled at the training's rate).
#pragma once

#include <Eigen/Dense>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/live_step.hpp"
#include "fitting/features.hpp"
#include "fitting/models.hpp"

namespace tt::fitting {

using core::LiveStep;
using core::SampleStatus;
using core::status_name;

/// A stream's past rows, kept to give a network the window it reads at the latest row: `steps`
/// entries `spacing` seconds apart ending at that row, each the kept rows linearly interpolated
/// in time (the first row before the stream's start). A row less than `keep_every` after the
/// last kept one is not kept, which bounds the memory of a dense stream to
/// (steps - 1)·spacing / keep_every rows; rows older than the window are let go.
class WindowHistory {
 public:
  /// Throws DataError unless steps >= 1 and spacing, keep_every > 0.
  WindowHistory(int steps, double spacing, double keep_every);
  /// The next row; its time exceeds the previous one's.
  void push(double time, const Eigen::VectorXd& row);
  /// steps x #row entries: the window ending at the latest row (empty before the first).
  Eigen::MatrixXd window() const;
  std::size_t kept() const { return kept_.size(); }

 private:
  /// the row at `time`, not after the latest
  Eigen::VectorXd row_at(double time) const;
  int steps_;
  double spacing_, keep_every_;
  std::deque<std::pair<double, Eigen::VectorXd>> kept_;
  double latest_time_ = 0.0;
  Eigen::VectorXd latest_;
};

/// Fitted models bound by name to the columns of a stream and stepped sample by sample.
class Compensator {
 public:
  /// models: any kind, their features named (sensor_names, input_names); columns: the names of
  /// a sample's values, sensors and inputs alike. Throws DataError naming the first column a model
  /// reads that `columns` lacks. sigma: #models standard deviations of the predictions [m], given
  /// with every step (empty: none). network_every_s: a network (cnn_bigru_attention) is evaluated
  /// at a sample at least this long after its last evaluation [s], its prediction held between;
  /// its window reads rows window_stride · sample_interval_s apart (throws DataError when the
  /// network does not say its sample interval).
  Compensator(const std::vector<FittedModel>& models, const std::vector<std::string>& columns,
              const Eigen::VectorXd& sigma = {}, double network_every_s = 1.0);

  /// The models on the next sample: time [s] and one value per column (temperatures [K] or °C,
  /// speed [rpm]), NaN where a reading is missing.
  const LiveStep& next(double time, const Eigen::Ref<const Eigen::VectorXd>& values);

  /// The columns the models read, ascending.
  const std::vector<int>& used_columns() const { return used_; }

 private:
  /// the prediction [m] of model m at the sample just taken into streams_[m]
  double value(std::size_t m, double time, const Eigen::VectorXd& row);

  std::vector<FittedModel> models_;
  std::vector<FeatureStream> streams_;
  /// per model: a network's past rows (nullopt for the other kinds), and its last evaluation
  std::vector<std::optional<WindowHistory>> windows_;
  std::vector<double> evaluated_at_;
  double network_every_s_;
  std::vector<int> used_;
  /// the last good reading of every column (NaN before one)
  Eigen::VectorXd last_good_, sample_;
  LiveStep step_;
  bool started_ = false;
};

}  // namespace tt::fitting
