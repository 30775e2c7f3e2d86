// The feed axis in `fit` (seed 004): models of the thermal error at the case's axis points, chosen
// on validation groups and tested like the TCP's; the patent's one network predicting every output
// (TCP and axis points) at once; and the axis polynomial a CNC would receive, fitted at every test
// time from each model's axis-point predictions and judged by what it leaves at the points.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "fitting/group.hpp"
#include "fitting/models.hpp"
#include "fitting/selection.hpp"

namespace tt::studies {

/// Target names of the axis points' error columns: "<point id>_dx", "_dy", "_dz" per point, in
/// the case's axis_points order (AxisError::values' column order).
std::vector<std::string> axis_target_names(const core::CaseSpec& spec);

/// Mean over the groups `which` of the standard deviation of error column `target` [m].
double uncompensated_std(const std::vector<fitting::Group>& groups, const std::vector<int>& which,
                         int target);

/// What the axis polynomial of one source leaves at the axis points over the test groups.
struct AxisCompensation {
  /// "uncompensated"; "measured" (the polynomial of the measured error itself: what no model can
  /// beat); "linear" (of the chosen linear models' predictions); "network"
  std::string source;
  std::array<double, 3> rms_m{};  /// per direction (x, y, z): over groups, points and times [m]
  std::array<double, 3> max_m{};  /// per direction: largest |residual| [m]
};

/// The axis points' models and polynomials.
struct AxisFit {
  std::vector<std::string> points;  /// axis point ids
  Eigen::VectorXd positions;        /// #points along the feed axis [m]
  std::string feed_axis;            /// the feed axis's name, e.g. "X"
  int direction = 0;                /// the coordinate it moves along: 0 x, 1 y, 2 z
  int degree = 0;                   /// of the axis polynomial
  std::vector<int> targets;         /// the groups' error columns: 3 per point (dx, dy, dz)
  /// per target: the candidate chosen on validation, refitted and tested
  std::vector<fitting::Evaluation> linear;
  std::vector<double> uncompensated_std;  /// per target, over the test groups [m]
  /// with a network: one model per error column of the groups (TCP targets, then axis targets),
  /// all sharing one network trained on the fitting and validation groups, and its test accuracy
  std::vector<fitting::FittedModel> network;
  std::vector<fitting::Accuracy> network_test;
  std::vector<AxisCompensation> compensation;
};

/// Each axis target's chosen linear model (fit.linear) on `group`: #samples x 3 #points [m], as
/// AxisError::values.
Eigen::MatrixXd linear_axis_predictions(const AxisFit& fit, const fitting::Group& group);

/// What the axis polynomial fitted at every time to each estimate (#samples x 3 #points of
/// `fit.points`, as AxisError::values) leaves at the points of the matching truth, over all of
/// them, as `source`. An estimate of zeros leaves the truth itself (uncompensated). Throws
/// SolverError when the counts of truths and estimates differ or an estimate's shape is not its
/// truth's.
AxisCompensation axis_compensation(const std::string& source, const AxisFit& fit,
                                   const std::vector<Eigen::MatrixXd>& truths,
                                   const std::vector<Eigen::MatrixXd>& estimates);

/// The axis points' error columns are groups' target columns [first_target, first_target + 3 n).
/// Each is chosen among `specs` on split.validation with the standard's correlation sets (m <= 4,
/// ranked on the fitting groups) and `extra_sets` (e.g. the TCP's chosen sets), and tested on
/// split.test. With `network`, one network (its spec, reading `network_sensors`) is trained on
/// every error column at once. Throws DataError when the split has no test group.
AxisFit axis_fit(const core::CaseSpec& spec, const std::vector<fitting::Group>& groups,
                 const fitting::Split& split, int first_target,
                 const std::vector<fitting::SensorSet>& extra_sets,
                 const std::vector<fitting::ModelSpec>& specs,
                 const std::optional<fitting::ModelSpec>& network,
                 const std::vector<int>& network_sensors);

}  // namespace tt::studies
