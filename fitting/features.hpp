// Regressors of a thermal-error model: the temperature increments of the chosen sensors and, for
// the dynamic model, their first-order low-pass filtered versions (distributed lags), because
// thermal error lags the temperatures read on the surface.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "fitting/group.hpp"

namespace tt::fitting {

/// Which columns of a group a model reads and how it turns them into regressors.
struct FeatureMap {
  /// columns of Group::temperature
  std::vector<int> sensors;
  /// names of those columns, kept for reports
  std::vector<std::string> sensor_names;
  /// low-pass time constants [s]; empty for a static model
  std::vector<double> time_constants;
  /// columns of Group::inputs read beside the temperatures (as increments, like them)
  std::vector<int> inputs;
  /// names of those columns, kept for reports
  std::vector<std::string> input_names;
};

/// Response y of the filter τ·y' + y = u to the samples u (taken as piecewise linear between
/// the #samples instants `time` [s]), with y(time_0) = u_0. Exact for piecewise-linear input, so
/// it holds on a non-uniform time grid.
Eigen::VectorXd low_pass(const Eigen::VectorXd& time, const Eigen::VectorXd& u, double tau);

/// One interval of low_pass: y at the end of an interval of h > 0 [s] over which u goes linearly
/// from u_previous to u, given y_previous at its start and decay = exp(−h/τ). The one formula that
/// low_pass and FeatureStream both step with.
inline double low_pass_step(double y_previous, double u_previous, double u, double h, double tau,
                            double decay) {
  const double slope = (u - u_previous) / h;
  // e = y − u obeys τe' = −e − τu' with u' constant over the interval.
  return u + (y_previous - u_previous) * decay - tau * slope * (1.0 - decay);
}

/// feature_matrix's rows one sample at a time, for a model read beside the machine: the first
/// sample is the reference of the increments, and every later one advances the low-pass filters
/// over the interval since the one before. feature_matrix is this stream run over a group.
class FeatureStream {
 public:
  /// map.sensors index the temperatures and map.inputs the inputs handed to next(); throws
  /// DataError on a time constant that is not > 0.
  explicit FeatureStream(const FeatureMap& map);

  /// The regressors of the next sample (a row of feature_matrix, in its column order).
  /// time [s] must exceed the previous sample's (throws DataError otherwise); temperature [K] and
  /// inputs (speed [rpm]) are one sample's values, read at the map's columns.
  const Eigen::VectorXd& next(double time, const Eigen::Ref<const Eigen::VectorXd>& temperature,
                              const Eigen::Ref<const Eigen::VectorXd>& inputs);

  /// false before the first sample
  bool started() const { return started_; }
  /// the time of the last sample taken [s]
  double last_time() const { return last_time_; }

 private:
  FeatureMap map_;
  /// #sensors + #inputs readings of the first sample
  Eigen::VectorXd reference_;
  /// #sensors + #inputs increments of the current and of the previous sample
  Eigen::VectorXd increments_, previous_;
  /// the regressors of the last sample
  Eigen::VectorXd features_;
  double last_time_ = 0.0;
  bool started_ = false;
};

/// #samples x ((#sensors + #inputs)·(1 + #time_constants)) regressors of one group: first the
/// increments ΔT_k [K], then the input increments (speed [rpm]), then for each time constant the
/// filtered versions of all of them in the same order.
Eigen::MatrixXd feature_matrix(const FeatureMap& map, const Group& group);

/// Names of feature_matrix's columns, e.g. "dT[t3]", "d[speed_rpm]" and "lp1800s(dT[t3])".
std::vector<std::string> feature_names(const FeatureMap& map);

/// The fitting rows of several groups stacked, each group's features computed on its own time.
struct StackedRows {
  /// #rows x #features regressors [K]
  Eigen::MatrixXd features;
  /// #rows errors of the target [m]
  Eigen::VectorXd error;
};

/// feature_matrix and error column `target` of every group, stacked in group order.
StackedRows stacked_rows(const FeatureMap& map, const std::vector<Group>& groups, int target);

}  // namespace tt::fitting
