// Live compensation: fitted models evaluated one sample at a time as a machine's sensors are read,
// giving exactly what predicted_error gives on the same samples taken as a group. A reading that
// is missing holds the sensor's last good value; a sample whose time does not advance is skipped.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "core/live_step.hpp"
#include "fitting/features.hpp"
#include "fitting/models.hpp"

namespace tt::fitting {

using core::LiveStep;
using core::SampleStatus;
using core::status_name;

/// Fitted models bound by name to the columns of a stream and stepped sample by sample.
class Compensator {
 public:
  /// models: linear kinds (no_compensation, least_squares, ridge, distributed_lag) or
  /// projection_pursuit, their features named (sensor_names, input_names); columns: the names of
  /// a sample's values, sensors and inputs alike. Throws DataError naming the first column a model
  /// reads that `columns` lacks, or a model kind it cannot step (cnn_bigru_attention). sigma:
  /// #models standard deviations of the predictions [m], given with every step (empty: none).
  Compensator(const std::vector<FittedModel>& models, const std::vector<std::string>& columns,
              const Eigen::VectorXd& sigma = {});

  /// The models on the next sample: time [s] and one value per column (temperatures [K] or °C,
  /// speed [rpm]), NaN where a reading is missing.
  const LiveStep& next(double time, const Eigen::Ref<const Eigen::VectorXd>& values);

  /// The columns the models read, ascending.
  const std::vector<int>& used_columns() const { return used_; }

 private:
  std::vector<FittedModel> models_;
  std::vector<FeatureStream> streams_;
  std::vector<int> used_;
  /// the last good reading of every column (NaN before one)
  Eigen::VectorXd last_good_, sample_;
  LiveStep step_;
  bool started_ = false;
};

}  // namespace tt::fitting
