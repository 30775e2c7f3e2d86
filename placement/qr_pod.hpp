// Sensor placement by QR pivoting on POD modes (the empirical-interpolation / Q-DEIM idea): the
// sensors are the candidates whose rows of the leading modes are the most independent. It does
// not look at the error at all: it picks points that best reconstruct the temperature field.
#pragma once

#include <Eigen/Dense>
#include <span>
#include <vector>

#include "placement/gaussian.hpp"

namespace tt::placement {

/// #candidates x r leading left singular vectors of the centred #candidates x #samples matrix
/// (each history minus its time mean), from the eigen-decomposition of the smaller Gram matrix.
/// Fewer than r columns when the numerical rank (σ > 1e-6·σ_max) is lower.
Eigen::MatrixXd pod_modes(const Eigen::MatrixXd& temperatures, int r);

/// Column-pivoted QR on the transposed modes (r x #candidates) restricted to `pool`: the first
/// pivot has the largest row norm, each next one the largest norm after projecting out the rows
/// chosen so far. Candidates that do not add a direction to the chosen histories (twins) are
/// skipped; exact ties go to the lower column. Stops early when the modes are exhausted.
std::vector<int> qr_pivots(const Eigen::MatrixXd& modes, std::span<const int> pool, int m,
                           const LinearProblem& linear, const Collinearity& guard);

}  // namespace tt::placement
