// Histories on a common time grid: the resampling to S samples that the patent's method starts
// from, and the centred unit-norm columns that the linear criteria work on.
#pragma once

#include <Eigen/Dense>

namespace tt::placement {

/// The S sample times t_k = t_first + k·(t_last − t_first)/S, k = 1..S [s]. The first time (the
/// initial state, where every history starts from the same value) is left out: on SB-1's grid
/// [0, 7200] s with S = 100 this gives the spec's t = 72·k s.
Eigen::VectorXd sample_times(const Eigen::VectorXd& times_s, int samples);

/// #new times x #columns: each column of `values` (#times x #columns) linearly interpolated at
/// `new_times_s`, which must lie inside [times_s(0), times_s(last)]. times_s strictly increasing.
Eigen::MatrixXd resampled(const Eigen::VectorXd& times_s, const Eigen::MatrixXd& values,
                          const Eigen::VectorXd& new_times_s);

/// #rows x #columns: each column minus its mean, scaled to unit Euclidean norm, so that the dot
/// product of two columns is their correlation coefficient. A constant column becomes zero.
Eigen::MatrixXd unit_columns(const Eigen::MatrixXd& values);

}  // namespace tt::placement
