// Linear models E = β0 + Σ β_k·φ_k: the standard's least squares (formula 4) and ridge
// regression, which shrinks the coefficients of nearly collinear temperatures.
#pragma once

#include <Eigen/Dense>

namespace tt::fitting {

/// E = intercept + features · coefficients.
struct LinearFit {
  /// β0 [m]
  double intercept = 0.0;
  /// #features β_k [m per feature unit, i.e. m/K]
  Eigen::VectorXd coefficients;
};

/// Minimises ||y − β0 − Φβ||² + λ·n·Σ_k (s_k β_k)², s_k the standard deviation of column k, so
/// λ is dimensionless and the intercept is not shrunk. λ = 0 is the standard's least squares
/// β = (AᵀA)⁻¹AᵀE with A = [1, X], solved by an orthogonal decomposition (the minimum-norm
/// solution when columns are collinear).
/// phi: #rows x #features regressors; y: #rows errors [m]; lambda >= 0.
LinearFit linear_fit(const Eigen::MatrixXd& phi, const Eigen::VectorXd& y, double lambda);

/// #rows predictions [m] of a linear fit on the regressors phi.
Eigen::VectorXd linear_prediction(const LinearFit& fit, const Eigen::MatrixXd& phi);

}  // namespace tt::fitting
