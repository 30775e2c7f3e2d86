#include "placement/estimation.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "core/dense_product.hpp"
#include "core/errors.hpp"
#include "core/timing.hpp"

namespace tt::placement {

namespace {

[[noreturn]] void fail(const std::string& what) {
  throw core::DataError("placement for estimation: " + what);
}

std::string shape(const Eigen::MatrixXd& m) {
  return std::to_string(m.rows()) + " x " + std::to_string(m.cols());
}

/// The covariance at the next reading before its update: F P F^T + Q, kept symmetric.
Eigen::MatrixXd predicted(const Eigen::MatrixXd& p, const Eigen::MatrixXd& f,
                          const Eigen::MatrixXd& q) {
  // core::dense_product, as the observer's: coefficient-wise for ~100 rows, blocked for several
  // hundred.
  const Eigen::MatrixXd fp = core::dense_product(f, p);
  const Eigen::MatrixXd fpf = core::dense_product(fp, f.transpose());
  return 0.5 * (fpf + fpf.transpose()) + q;
}

/// The posterior covariance at every reading of every track with `columns` reading, one rank-one
/// update per sensor (independent noises: the same as one update by all), handed to `visit`.
template <class Visit>
void posterior_pass(const EstimationProblem& p, std::span<const int> columns, Visit&& visit) {
  for (const CovarianceTrack& track : p.tracks) {
    Eigen::MatrixXd cov = track.initial;
    for (std::size_t k = 0; k < track.transitions.size(); ++k) {
      cov = predicted(cov, track.transitions[k], track.process[k]);
      for (int c : columns) {
        const double sigma = p.candidate_sigma(c);
        cov = updated_covariance(cov, p.candidate_rows.row(c).transpose(), sigma * sigma);
      }
      visit(cov);
    }
  }
}

std::size_t readings(const EstimationProblem& p) {
  std::size_t n = 0;
  for (const auto& t : p.tracks) n += t.transitions.size();
  return n;
}

}  // namespace

void validate(const EstimationProblem& p, Eigen::Index candidates, Eigen::Index targets) {
  if (p.tracks.empty()) fail("no run to place on: expected at least one covariance track");
  const Eigen::Index n = p.tracks.front().initial.rows();
  if (n == 0) fail("the filter has no state");
  if (p.candidate_rows.rows() != candidates || p.candidate_rows.cols() != n)
    fail("candidate rows " + shape(p.candidate_rows) + ": expected " + std::to_string(candidates) +
         " candidates x " + std::to_string(n) + " states");
  if (p.target_rows.rows() != targets || p.target_rows.cols() != n)
    fail("target rows " + shape(p.target_rows) + ": expected " + std::to_string(targets) +
         " targets x " + std::to_string(n) + " states");
  if (p.candidate_sigma.size() != candidates || !(p.candidate_sigma.array() > 0).all() ||
      !p.candidate_sigma.allFinite())
    fail(std::to_string(p.candidate_sigma.size()) + " sensor sigmas for " +
         std::to_string(candidates) + " candidates: expected one finite value > 0 K each");
  if (!p.candidate_rows.allFinite() || !p.target_rows.allFinite())
    fail("the candidate or target rows hold NaN or infinity");
  for (std::size_t r = 0; r < p.tracks.size(); ++r) {
    const CovarianceTrack& t = p.tracks[r];
    const std::string run = "run " + std::to_string(r) + ": ";
    if (t.transitions.empty()) fail(run + "no reading");
    if (t.transitions.size() != t.process.size())
      fail(run + std::to_string(t.transitions.size()) + " transitions and " +
           std::to_string(t.process.size()) +
           " process covariances: expected one of each per "
           "reading");
    const auto square = [&](const Eigen::MatrixXd& m, const std::string& what) {
      if (m.rows() != n || m.cols() != n || !m.allFinite())
        fail(run + what + " is " + shape(m) + " (or holds NaN): expected " + std::to_string(n) +
             " x " + std::to_string(n));
    };
    square(t.initial, "the initial covariance");
    for (std::size_t k = 0; k < t.transitions.size(); ++k) {
      square(t.transitions[k], "transition " + std::to_string(k));
      square(t.process[k], "process covariance " + std::to_string(k));
    }
  }
}

Eigen::MatrixXd updated_covariance(const Eigen::MatrixXd& p, const Eigen::VectorXd& h,
                                   double sigma2) {
  const Eigen::VectorXd ph = p * h;
  const double s = h.dot(ph) + sigma2;
  return p - (ph / s) * ph.transpose();
}

Eigen::VectorXd mean_posterior_variance(const EstimationProblem& p, std::span<const int> columns) {
  const auto m = static_cast<Eigen::Index>(columns.size());
  Eigen::MatrixXd h(m, p.candidate_rows.cols());
  Eigen::VectorXd r2(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const int c = columns[static_cast<std::size_t>(i)];
    h.row(i) = p.candidate_rows.row(c);
    r2(i) = p.candidate_sigma(c) * p.candidate_sigma(c);
  }
  const Eigen::MatrixXd& l = p.target_rows;
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(l.rows());
  for (const CovarianceTrack& track : p.tracks) {
    Eigen::MatrixXd cov = track.initial;
    for (std::size_t k = 0; k < track.transitions.size(); ++k) {
      cov = predicted(cov, track.transitions[k], track.process[k]);
      if (m > 0) {
        // P - P H^T S^-1 H P with S = H P H^T + R = L L^T: P - W^T W, W = L^-1 H P.
        const Eigen::MatrixXd hp = h.lazyProduct(cov);
        Eigen::MatrixXd s = hp.lazyProduct(h.transpose());
        s.diagonal() += r2;
        const Eigen::LLT<Eigen::MatrixXd> llt(s);
        if (llt.info() != Eigen::Success) fail("the readings' covariance is not positive definite");
        const Eigen::MatrixXd w = llt.matrixL().solve(hp);
        cov -= w.transpose().lazyProduct(w);
      }
      sum += l.lazyProduct(cov).cwiseProduct(l).rowwise().sum();
    }
  }
  return sum / static_cast<double>(readings(p));
}

GreedyPath estimation_greedy(const EstimationProblem& p, std::span<const int> pool, int m_max,
                             std::span<const int> targets, const Admissible& admissible) {
  const auto start = std::chrono::steady_clock::now();
  const Eigen::Index nt = static_cast<Eigen::Index>(targets.size());
  Eigen::MatrixXd l(nt, p.target_rows.cols());
  for (Eigen::Index t = 0; t < nt; ++t) {
    const int target = targets[static_cast<std::size_t>(t)];
    if (target < 0 || target >= p.target_rows.rows())
      fail("target " + std::to_string(target) + " of " + std::to_string(p.target_rows.rows()));
    l.row(t) = p.target_rows.row(target);
  }
  std::vector<int> left(pool.begin(), pool.end());
  const auto rows_of = [&](const std::vector<int>& columns) {
    Eigen::MatrixXd h(static_cast<Eigen::Index>(columns.size()), p.candidate_rows.cols());
    Eigen::VectorXd r2(h.rows());
    for (Eigen::Index i = 0; i < h.rows(); ++i) {
      const int c = columns[static_cast<std::size_t>(i)];
      h.row(i) = p.candidate_rows.row(c);
      r2(i) = p.candidate_sigma(c) * p.candidate_sigma(c);
    }
    return std::pair{h, r2};
  };
  const double count = static_cast<double>(readings(p));
  GreedyPath path;
  for (int step = 0; step <= m_max; ++step) {
    // The filter under the chosen sensors; each candidate's reading as the next rank-one update
    // at every reading: its reduction of the targets' variance, (l P h)^2 / (h^T P h + sigma^2).
    const auto [h, r2] = rows_of(left);
    Eigen::VectorXd reduction = Eigen::VectorXd::Zero(h.rows());
    double criterion = 0;
    const bool scoring = step < m_max && !left.empty();
    posterior_pass(p, path.order, [&](const Eigen::MatrixXd& cov) {
      const Eigen::MatrixXd lp = l.lazyProduct(cov);  // nt x n
      criterion += lp.cwiseProduct(l).sum();
      if (!scoring) return;
      const Eigen::MatrixXd hp = h.lazyProduct(cov);  // #left x n
      const Eigen::VectorXd s = hp.cwiseProduct(h).rowwise().sum() + r2;
      const Eigen::MatrixXd hpl = hp.lazyProduct(l.transpose());  // #left x nt
      reduction += (hpl.rowwise().squaredNorm().array() / s.array()).matrix();
    });
    if (step > 0) {
      path.scores.push_back(criterion / count);
      path.seconds.push_back(core::seconds_since(start));
    }
    if (!scoring) break;
    // Best first (exact ties: the lower column); the first admissible one is taken.
    std::vector<std::size_t> order(left.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      const auto ia = static_cast<Eigen::Index>(a), ib = static_cast<Eigen::Index>(b);
      if (reduction(ia) != reduction(ib)) return reduction(ia) > reduction(ib);
      return left[a] < left[b];
    });
    std::size_t best = left.size();
    for (std::size_t i : order) {
      // A candidate that lowers nothing (e.g. a row of zeros) is no sensor: none after it is.
      if (!(reduction(static_cast<Eigen::Index>(i)) > 1e-14 * criterion)) break;
      if (!admissible || admissible(path.order, left[i])) {
        best = i;
        break;
      }
    }
    if (best == left.size()) break;
    path.order.push_back(left[static_cast<std::size_t>(best)]);
    left.erase(left.begin() + best);
  }
  return path;
}

}  // namespace tt::placement
