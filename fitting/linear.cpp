#include "fitting/linear.hpp"

#include <cmath>
#include <string>

#include "core/errors.hpp"
#include "core/finite.hpp"

namespace tt::fitting {

namespace {

/// A fit whose numbers overflowed is refused, never written as a model.
LinearFit checked(LinearFit fit) {
  const std::string origin =
      "the regressors or errors it was fitted on hold a NaN, an infinity or numbers beyond a "
      "double's range";
  core::require_finite(fit.intercept, "a fitted intercept", origin);
  core::require_finite(fit.coefficients, "a fitted coefficient (row: regressor)", origin);
  return fit;
}

}  // namespace

LinearFit linear_fit(const Eigen::MatrixXd& phi, const Eigen::VectorXd& y, double lambda) {
  if (!(lambda >= 0.0))
    throw core::DataError("ridge lambda = " + std::to_string(lambda) + ": must be >= 0");
  const Eigen::Index n = phi.rows();
  const Eigen::Index p = phi.cols();
  if (y.size() != n)
    throw core::DataError("linear fit: " + std::to_string(n) + " regressor rows but " +
                          std::to_string(y.size()) + " errors");
  if (n < p + 1)
    throw core::DataError("linear fit: " + std::to_string(n) + " samples for " +
                          std::to_string(p + 1) +
                          " coefficients; hint: use fewer sensors or more readings");
  LinearFit fit;
  if (lambda == 0.0) {
    Eigen::MatrixXd a(n, p + 1);
    a.col(0).setOnes();
    a.rightCols(p) = phi;
    const Eigen::VectorXd beta = a.completeOrthogonalDecomposition().solve(y);
    fit.intercept = beta(0);
    fit.coefficients = beta.tail(p);
    return checked(fit);
  }
  const Eigen::RowVectorXd mean = phi.colwise().mean();
  const Eigen::MatrixXd centred = phi.rowwise() - mean;
  const double y_mean = y.mean();
  Eigen::VectorXd scale(p);
  for (Eigen::Index k = 0; k < p; ++k) {
    const double s = std::sqrt(centred.col(k).squaredNorm() / static_cast<double>(n));
    scale(k) = s > 0.0 ? s : 1.0;
  }
  const Eigen::MatrixXd z = centred * scale.cwiseInverse().asDiagonal();
  Eigen::MatrixXd normal = z.transpose() * z;
  normal.diagonal().array() += lambda * static_cast<double>(n);
  const Eigen::VectorXd b = normal.ldlt().solve(z.transpose() * (y.array() - y_mean).matrix());
  fit.coefficients = b.cwiseQuotient(scale);
  fit.intercept = y_mean - mean.dot(fit.coefficients);
  return checked(fit);
}

Eigen::VectorXd linear_prediction(const LinearFit& fit, const Eigen::MatrixXd& phi) {
  if (phi.cols() != fit.coefficients.size())
    throw core::DataError("linear prediction: " + std::to_string(phi.cols()) +
                          " regressors for a model of " + std::to_string(fit.coefficients.size()));
  return (phi * fit.coefficients).array() + fit.intercept;
}

}  // namespace tt::fitting
