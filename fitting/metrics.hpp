// The standard's accuracy and robustness metrics (DB3401/T 326-2024 section 9).
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace tt::fitting {

/// Formula 5, the prediction residual standard deviation of one group of N >= 2 readings:
/// S = sqrt( Σ (E_i − Ê_i)² / (N − 1) ), from the #samples residuals E − Ê [m].
double residual_std(const Eigen::VectorXd& residual);

/// A model's accuracy over K groups.
struct Accuracy {
  /// K prediction residual standard deviations S_i, one per group [m]
  std::vector<double> s;
  /// formula 6, S_M = mean of S_i [m]
  double sm = 0.0;
  /// formula 7, S_σ = sqrt( Σ (S_i − S_M)² / (K − 1) ) [m]; NaN when K = 1 (the standard
  /// assesses no robustness on a single group)
  double s_sigma = 0.0;
};

/// S_M and S_σ of the per-group S_i [m]; throws DataError when s is empty.
Accuracy accuracy(const std::vector<double>& s);

/// The mean of S_i² over the groups [m²]: what an RMS over equally weighted groups squares. Unlike
/// S_M, one group with a large S weighs in full. Throws DataError when a.s is empty.
double mean_square(const Accuracy& a);

}  // namespace tt::fitting
