#include "solvers/axis_error.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "core/errors.hpp"

namespace tt::solvers {
namespace {

Eigen::MatrixXd vandermonde(const Eigen::VectorXd& p, int degree) {
  Eigen::MatrixXd a(p.size(), degree + 1);
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    double x = 1;
    for (int k = 0; k <= degree; ++k, x *= p(i)) a(i, k) = x;
  }
  return a;
}

}  // namespace

AxisError axis_error(const mesh::TetMesh& m, const core::CaseSpec& spec, const Eigen::MatrixXd& u) {
  const auto& ids = spec.mechanical.axis_points;
  Eigen::MatrixXd at_points(u.cols(), 3 * static_cast<Eigen::Index>(ids.size()));
  for (size_t i = 0; i < ids.size(); ++i) {
    const int node = mesh::named_node(m, ids[i]);
    if (node < 0)
      throw core::SolverError("mechanical.axis_points: '" + ids[i] +
                              "' is not a named point of the mesh");
    for (int d = 0; d < 3; ++d)
      at_points.col(static_cast<Eigen::Index>(3 * i) + d) = u.row(3 * node + d).transpose();
  }
  return axis_error_at_points(spec, at_points);
}

AxisError axis_error_at_points(const core::CaseSpec& spec, const Eigen::MatrixXd& u) {
  AxisError e;
  const auto& ids = spec.mechanical.axis_points;
  const auto n = static_cast<Eigen::Index>(ids.size());
  if (u.cols() != 3 * n)
    throw core::SolverError("axis point displacements with " + std::to_string(u.cols()) +
                            " columns for " + std::to_string(n) +
                            " axis points; expected 3 per point (dx, dy, dz)");
  e.points = ids;
  e.positions.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& id = ids[static_cast<size_t>(i)];
    const auto p = std::find_if(spec.points.begin(), spec.points.end(),
                                [&](const auto& q) { return q.id == id; });
    if (p == spec.points.end())
      throw core::SolverError("mechanical.axis_points: '" + id +
                              "' is not a named point of the case");
    e.positions(i) = p->position(spec.feed_axis.direction);
  }
  e.values = u.rows() > 0 ? Eigen::MatrixXd(u.rowwise() - u.row(0)) : u;
  return e;
}

AxisPolynomial axis_polynomial(const AxisError& e, int degree) {
  const Eigen::Index n = e.positions.size();
  if (degree < 0 || n < degree + 1)
    throw core::SolverError(
        "axis polynomial of degree " + std::to_string(degree) + " on " + std::to_string(n) +
        " points: needs at least degree + 1 points; add axis_points or lower the degree");
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = i + 1; j < n; ++j)
      if (e.positions(i) == e.positions(j))
        throw core::SolverError("axis points " + e.points[static_cast<size_t>(i)] + " and " +
                                e.points[static_cast<size_t>(j)] +
                                " share their axis position: a polynomial cannot tell them apart");
  // Centred and scaled positions keep the least-squares problem well conditioned; the
  // coefficients are mapped back to powers of the position itself.
  const double centre = 0.5 * (e.positions.maxCoeff() + e.positions.minCoeff());
  const double half = std::max(0.5 * (e.positions.maxCoeff() - e.positions.minCoeff()), 1e-300);
  const Eigen::VectorXd s = (e.positions.array() - centre) / half;
  const Eigen::MatrixXd a = vandermonde(s, degree);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  // b_k (scaled) -> c_j: sum_k b_k ((p - centre)/half)^k expanded by the binomial theorem.
  Eigen::MatrixXd to_c = Eigen::MatrixXd::Zero(degree + 1, degree + 1);  // c = to_c * b
  for (int k = 0; k <= degree; ++k) {
    double binom = 1;  // C(k, j)
    for (int j = 0; j <= k; ++j) {
      to_c(j, k) = binom * std::pow(-centre, k - j) / std::pow(half, k);
      binom = binom * (k - j) / (j + 1);
    }
  }
  AxisPolynomial poly;
  poly.degree = degree;
  const Eigen::Index times = e.values.rows();
  for (int d = 0; d < 3; ++d) {
    Eigen::MatrixXd y(n, times);
    for (Eigen::Index i = 0; i < n; ++i) y.row(i) = e.values.col(3 * i + d).transpose();
    const Eigen::MatrixXd b = qr.solve(y);  // (degree + 1) x #times
    const Eigen::MatrixXd r = a * b - y;    // #points x #times residuals
    poly.coefficients[d] = (to_c * b).transpose();
    poly.rms[d] = (r.colwise().squaredNorm() / static_cast<double>(n)).cwiseSqrt().transpose();
    poly.max[d] = r.cwiseAbs().colwise().maxCoeff().transpose();
  }
  return poly;
}

Eigen::VectorXd axis_polynomial_value(const AxisPolynomial& poly, int direction, Eigen::Index time,
                                      const Eigen::VectorXd& p) {
  const Eigen::VectorXd c = poly.coefficients[direction].row(time).transpose();
  Eigen::VectorXd v = Eigen::VectorXd::Constant(p.size(), c(poly.degree));
  for (int k = poly.degree - 1; k >= 0; --k) v = (v.array() * p.array() + c(k)).matrix();
  return v;
}

Eigen::MatrixXd axis_polynomial_residual(const AxisPolynomial& poly, const AxisError& measured) {
  const Eigen::Index n = measured.positions.size();
  if (poly.coefficients[0].rows() != measured.values.rows() || measured.values.cols() != 3 * n)
    throw core::SolverError("axis polynomial of " + std::to_string(poly.coefficients[0].rows()) +
                            " times against an axis error of " +
                            std::to_string(measured.values.rows()) + " times and " +
                            std::to_string(measured.values.cols()) + " columns for " +
                            std::to_string(n) + " points; expected the same times, 3 per point");
  Eigen::MatrixXd r(measured.values.rows(), 3 * n);
  for (Eigen::Index t = 0; t < r.rows(); ++t)
    for (int d = 0; d < 3; ++d) {
      const Eigen::VectorXd fit = axis_polynomial_value(poly, d, t, measured.positions);
      for (Eigen::Index i = 0; i < n; ++i) r(t, 3 * i + d) = measured.values(t, 3 * i + d) - fit(i);
    }
  return r;
}

}  // namespace tt::solvers
