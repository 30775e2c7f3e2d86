#include "placement/gaussian.hpp"

#include <chrono>
#include <cmath>
#include <string>

#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "core/timing.hpp"
#include "placement/series.hpp"

namespace tt::placement {

using core::seconds_since;

LinearProblem linear_problem(const Eigen::MatrixXd& temperatures, const Eigen::VectorXd& error) {
  if (temperatures.rows() != error.size() || error.size() < 3)
    throw core::DataError("placement: " + std::to_string(temperatures.rows()) +
                          " temperature samples and " + std::to_string(error.size()) +
                          " error samples: expected the same number, at least 3");
  LinearProblem p;
  p.z = unit_columns(temperatures);
  p.y = unit_columns(error);
  if (p.y.norm() == 0.0)
    throw core::DataError("placement: the error target is constant: nothing to place sensors for");
  p.r_y.resize(p.z.cols());
  core::parallel_for(p.z.cols(), [&](std::ptrdiff_t j) { p.r_y(j) = p.z.col(j).dot(p.y); });
  return p;
}

double gaussian_mi_bits(double r_squared) {
  const double r2 = std::clamp(r_squared, 0.0, 1.0 - 1e-15);
  return -0.5 * std::log2(1.0 - r2);
}

bool adds_direction(const LinearProblem& problem, std::span<const int> chosen, int c,
                    const Collinearity& guard) {
  const double zc2 = problem.z.col(c).squaredNorm();
  if (zc2 == 0.0) return false;
  const auto k = static_cast<Eigen::Index>(chosen.size());
  if (k == 0) return true;
  Eigen::MatrixXd g(k, k);
  Eigen::VectorXd b(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    b(i) = problem.z.col(chosen[i]).dot(problem.z.col(c));
    if (std::abs(b(i)) > guard.max_correlation) return false;
    for (Eigen::Index j = 0; j <= i; ++j)
      g(i, j) = g(j, i) = problem.z.col(chosen[i]).dot(problem.z.col(chosen[j]));
  }
  const double residual = zc2 - b.dot(g.ldlt().solve(b));
  return residual >= guard.min_residual;
}

std::optional<double> set_r_squared(const LinearProblem& problem, std::span<const int> set,
                                    const Collinearity& guard) {
  const auto k = static_cast<Eigen::Index>(set.size());
  Eigen::MatrixXd l = Eigen::MatrixXd::Zero(k, k);
  Eigen::VectorXd w(k);  // L⁻¹ r_y, built row by row
  for (Eigen::Index i = 0; i < k; ++i) {
    if (problem.z.col(set[i]).squaredNorm() == 0.0) return std::nullopt;
    for (Eigen::Index j = 0; j < i; ++j) {
      const double r = problem.z.col(set[i]).dot(problem.z.col(set[j]));
      if (std::abs(r) > guard.max_correlation) return std::nullopt;
      l(i, j) = (r - l.row(i).head(j).dot(l.row(j).head(j))) / l(j, j);
    }
    // The Cholesky pivot is the share of variance left after projection on the members before.
    const double d = 1.0 - l.row(i).head(i).squaredNorm();
    if (!(d >= guard.min_residual)) return std::nullopt;
    l(i, i) = std::sqrt(d);
    w(i) = (problem.r_y(set[i]) - l.row(i).head(i).dot(w.head(i))) / l(i, i);
  }
  return w.squaredNorm();
}

GreedyPath gaussian_greedy(const LinearProblem& problem, std::span<const int> pool, int m_max,
                           const Collinearity& guard) {
  const auto start = std::chrono::steady_clock::now();
  const auto n = static_cast<std::ptrdiff_t>(pool.size());
  // Squared norm of each pool candidate's residual after projection on the chosen ones; the
  // error's residual r stays orthogonal to them, so r·z_c equals r·(residual of z_c).
  std::vector<double> norm2(pool.size());
  for (std::ptrdiff_t i = 0; i < n; ++i) norm2[i] = problem.z.col(pool[i]).squaredNorm();
  std::vector<char> taken(pool.size(), 0);
  std::vector<double> max_r(pool.size(), 0.0);  // largest |r| with a chosen sensor
  std::vector<Eigen::VectorXd> basis;
  Eigen::VectorXd r = problem.y;
  GreedyPath path;
  std::vector<double> gain(pool.size());
  for (int step = 0; step < m_max; ++step) {
    core::parallel_for(n, [&](std::ptrdiff_t i) {
      const double a = problem.z.col(pool[i]).dot(r);
      const bool ok = !taken[i] && norm2[i] > 0.0 && max_r[i] <= guard.max_correlation &&
                      norm2[i] >= guard.min_residual;
      gain[i] = ok ? a * a / norm2[i] : -1.0;
    });
    std::ptrdiff_t best = -1;
    for (std::ptrdiff_t i = 0; i < n; ++i)
      if (gain[i] >= 0.0 && (best < 0 || gain[i] > gain[best])) best = i;
    if (best < 0) break;
    taken[best] = 1;
    // Twice-orthogonalised new direction (Gram-Schmidt loses orthogonality otherwise).
    Eigen::VectorXd q = problem.z.col(pool[best]);
    for (int pass = 0; pass < 2; ++pass)
      for (const auto& b : basis) q -= b.dot(q) * b;
    q.normalize();
    r -= q.dot(r) * q;
    basis.push_back(q);
    const auto chosen = problem.z.col(pool[best]);
    core::parallel_for(n, [&](std::ptrdiff_t i) {
      const double a = problem.z.col(pool[i]).dot(q);
      norm2[i] -= a * a;
      max_r[i] = std::max(max_r[i], std::abs(problem.z.col(pool[i]).dot(chosen)));
    });
    path.order.push_back(pool[best]);
    path.scores.push_back(gaussian_mi_bits(1.0 - r.squaredNorm()));
    path.seconds.push_back(seconds_since(start));
  }
  return path;
}

}  // namespace tt::placement
