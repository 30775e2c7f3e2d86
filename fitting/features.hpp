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
