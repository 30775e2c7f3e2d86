#include "placement/baselines.hpp"

#include <algorithm>
#include <numeric>
#include <string>

#include "core/errors.hpp"
#include "core/parallel.hpp"

namespace tt::placement {

namespace {

/// (x − mean) / sample standard deviation; a constant series becomes zero.
Eigen::MatrixXd z_scored(const Eigen::MatrixXd& values) {
  Eigen::MatrixXd z = values.rowwise() - values.colwise().mean();
  const double dof = std::max<double>(1.0, static_cast<double>(values.rows()) - 1.0);
  for (Eigen::Index j = 0; j < z.cols(); ++j) {
    const double sd = std::sqrt(z.col(j).squaredNorm() / dof);
    if (sd > 0.0) z.col(j) /= sd;
  }
  return z;
}

/// Candidate columns ordered by descending score, exact ties to the lower column.
std::vector<int> order_descending(const Eigen::VectorXd& scores, std::span<const int> pool) {
  std::vector<int> order(pool.begin(), pool.end());
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    if (scores(a) != scores(b)) return scores(a) > scores(b);
    return a < b;
  });
  return order;
}

}  // namespace

Eigen::VectorXd grey_relational_grades(const Eigen::MatrixXd& temperatures,
                                       const Eigen::VectorXd& error, double rho) {
  if (!(rho > 0.0 && rho <= 1.0))
    throw core::DataError("placement.grey_rho = " + std::to_string(rho) +
                          ": must be in (0, 1] (0.5 is usual)");
  if (temperatures.rows() != error.size())
    throw core::DataError("placement: " + std::to_string(temperatures.rows()) +
                          " temperature samples but " + std::to_string(error.size()) +
                          " error samples");
  const Eigen::MatrixXd x = z_scored(temperatures);
  const Eigen::VectorXd y = z_scored(error);
  const Eigen::MatrixXd delta = (x.colwise() - y).cwiseAbs();
  const double dmin = delta.minCoeff();
  const double dmax = delta.maxCoeff();
  Eigen::VectorXd grades(x.cols());
  if (dmax == 0.0) return grades.setOnes();
  core::parallel_for(x.cols(), [&](std::ptrdiff_t i) {
    grades(i) = ((dmin + rho * dmax) / (delta.col(i).array() + rho * dmax)).mean();
  });
  return grades;
}

std::vector<int> top_ranked(const Eigen::VectorXd& scores, std::span<const int> pool, int m,
                            const LinearProblem& linear, const Collinearity& guard) {
  std::vector<int> chosen;
  for (int c : order_descending(scores, pool)) {
    if (static_cast<int>(chosen.size()) == m) break;
    if (adds_direction(linear, chosen, c, guard)) chosen.push_back(c);
  }
  return chosen;
}

std::vector<int> ranks_descending(const Eigen::VectorXd& scores) {
  std::vector<int> all(static_cast<std::size_t>(scores.size()));
  std::iota(all.begin(), all.end(), 0);
  const auto order = order_descending(scores, all);
  std::vector<int> rank(order.size());
  for (std::size_t r = 0; r < order.size(); ++r)
    rank[static_cast<std::size_t>(order[r])] = static_cast<int>(r) + 1;
  return rank;
}

}  // namespace tt::placement
