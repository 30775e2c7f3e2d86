#include "placement/qr_pod.hpp"

#include <string>

#include "core/errors.hpp"

namespace tt::placement {

Eigen::MatrixXd pod_modes(const Eigen::MatrixXd& temperatures, int r) {
  if (r < 1)
    throw core::DataError("placement: " + std::to_string(r) + " POD modes requested: need >= 1");
  // X = centred histories, #samples x #candidates here (the transpose of the snapshot matrix).
  const Eigen::MatrixXd x = temperatures.rowwise() - temperatures.colwise().mean();
  const Eigen::Index n = x.cols();
  const Eigen::Index s = x.rows();
  const bool by_samples = n > s;  // decompose the smaller Gram matrix
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(by_samples ? s : n, by_samples ? s : n);
  // A symmetric rank update (SYRK) is not split across threads by Eigen, so the modes are the
  // same bits whatever the thread count.
  if (by_samples)
    gram.selfadjointView<Eigen::Lower>().rankUpdate(x);
  else
    gram.selfadjointView<Eigen::Lower>().rankUpdate(x.transpose());
  gram = gram.selfadjointView<Eigen::Lower>();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(gram);
  if (eig.info() != Eigen::Success)
    throw core::DataError("placement: the eigen-decomposition of the " +
                          std::to_string(gram.rows()) +
                          "-square Gram matrix of the histories failed; hint: check for NaN");
  const Eigen::Index dim = gram.rows();
  const double lambda_max = std::max(eig.eigenvalues()(dim - 1), 0.0);
  // σ_i > 1e-6·σ_max  <=>  λ_i > 1e-12·λ_max: the Gram matrix squares the condition number,
  // so round-off puts spurious eigenvalues near 1e-16·λ_max.
  Eigen::Index rank = 0;
  while (rank < std::min<Eigen::Index>(r, dim) &&
         eig.eigenvalues()(dim - 1 - rank) > 1e-12 * lambda_max && lambda_max > 0.0)
    ++rank;
  Eigen::MatrixXd modes(n, rank);
  for (Eigen::Index i = 0; i < rank; ++i) {
    const Eigen::Index e = dim - 1 - i;  // eigenvalues ascend
    if (by_samples) {
      // u = X^T v / σ, one matrix-vector product per mode (no threaded GEMM).
      Eigen::VectorXd u = x.transpose() * eig.eigenvectors().col(e);
      modes.col(i) = u / std::sqrt(eig.eigenvalues()(e));
    } else {
      modes.col(i) = eig.eigenvectors().col(e);
    }
    // The sign of a singular vector is arbitrary; fix it so the largest entry is positive.
    Eigen::Index arg = 0;
    modes.col(i).cwiseAbs().maxCoeff(&arg);
    if (modes(arg, i) < 0.0) modes.col(i) = -modes.col(i);
  }
  return modes;
}

std::vector<int> qr_pivots(const Eigen::MatrixXd& modes, std::span<const int> pool, int m,
                           const LinearProblem& linear, const Collinearity& guard) {
  // Rows of the modes restricted to the pool, projected as pivots are chosen.
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(pool.size()), modes.cols());
  for (std::size_t i = 0; i < pool.size(); ++i)
    rows.row(static_cast<Eigen::Index>(i)) = modes.row(pool[i]);
  const double initial = rows.rowwise().squaredNorm().maxCoeff();
  std::vector<int> chosen;
  std::vector<char> taken(pool.size(), 0);
  while (static_cast<int>(chosen.size()) < m) {
    Eigen::Index best = -1;
    double best_norm = 0.0;
    for (Eigen::Index i = 0; i < rows.rows(); ++i) {
      if (taken[static_cast<std::size_t>(i)]) continue;
      const double norm = rows.row(i).squaredNorm();
      if (norm > best_norm && norm > 1e-20 * initial &&
          adds_direction(linear, chosen, pool[static_cast<std::size_t>(i)], guard)) {
        best = i;
        best_norm = norm;
      }
    }
    if (best < 0) break;
    taken[static_cast<std::size_t>(best)] = 1;
    chosen.push_back(pool[static_cast<std::size_t>(best)]);
    const Eigen::RowVectorXd q = rows.row(best) / std::sqrt(best_norm);
    rows -= (rows * q.transpose()) * q;
  }
  return chosen;
}

}  // namespace tt::placement
