// Projection pursuit regression with polynomial ridge functions (the seed method 002):
// ŷ = ȳ + Σ_m f_m(a_mᵀ x), each f_m a polynomial of one projection of the inputs.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <vector>

namespace tt::fitting {

struct PprOptions {
  /// random directions drawn in [−1, 1]^p for each ridge function
  int directions = 200;
  /// degree of each ridge polynomial
  int degree = 3;
  /// at most this many ridge functions
  int max_terms = 4;
  /// directions whose R² lies within this of the best form its cluster (the seed's ε = 0.02)
  double cluster_epsilon = 0.02;
  /// stop adding ridge functions once sqrt(Σ r² / Σ (y − ȳ)²) falls below this (the seed's 8 %)
  double relative_error_goal = 0.08;
  /// stop when a new ridge function explains less than this fraction of the residual's variance
  double min_gain = 1e-3;
  /// refine each direction by Gauss–Newton and backfit earlier terms after each new one
  bool refine = true;
  /// master seed of the direction draws; term m uses stream m
  std::uint64_t seed = 1;
};

/// One ridge function f(aᵀx) on standardised inputs.
struct RidgeFunction {
  /// #inputs unit projection direction
  Eigen::VectorXd direction;
  /// range of the projections z = aᵀx on the fitting rows; t = (2z − low − high)/(high − low)
  double z_low = 0.0;
  double z_high = 0.0;
  /// degree + 1 coefficients in ascending powers of t [m]; outside t ∈ [−1, 1] the function
  /// continues along its tangent, because a cubic running away beyond the fitted range is how a
  /// polynomial model fails on a new run
  Eigen::VectorXd polynomial;
  /// coefficient of determination of this term on the residual it was fitted to
  double r_squared = 0.0;
  /// number of random directions in the cluster this direction came from
  int cluster_size = 0;
};

struct PprModel {
  /// #inputs means and standard deviations: inputs enter as (x − center)/scale
  Eigen::VectorXd center;
  Eigen::VectorXd scale;
  /// ȳ [m]
  double mean = 0.0;
  std::vector<RidgeFunction> terms;
};

/// Fits a PPR model. x: #rows x #inputs (e.g. temperature increments [K]); y: #rows errors [m].
PprModel ppr_fit(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const PprOptions& options);

/// #rows predictions [m] for the inputs x (#rows x #inputs).
Eigen::VectorXd ppr_prediction(const PprModel& model, const Eigen::MatrixXd& x);

/// Values of one ridge function at the standardised inputs xs (#rows x #inputs) [m].
Eigen::VectorXd ridge_values(const RidgeFunction& ridge, const Eigen::MatrixXd& xs);

}  // namespace tt::fitting
