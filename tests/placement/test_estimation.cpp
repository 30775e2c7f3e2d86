// Placement for estimation (placement/estimation): the rank-one measurement update equals a fresh
// batch update, the greedy's reported criterion equals the set's criterion computed afresh, the
// greedy takes the sensor that obviously informs the target, and place_all carries the method.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <vector>

#include "core/errors.hpp"
#include "placement/estimation.hpp"
#include "placement/place.hpp"
#include "synthetic.hpp"

namespace tt::placement {
namespace {

/// A random symmetric positive definite n x n matrix.
Eigen::MatrixXd spd(synthetic::Normal& normal, Eigen::Index n) {
  Eigen::MatrixXd a(n, n);
  for (Eigen::Index j = 0; j < n; ++j) a.col(j) = normal.vector(n);
  return a * a.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
}

/// A random filter on n states read by `candidates` random rows, over two runs.
EstimationProblem random_problem(std::uint64_t seed, Eigen::Index n, Eigen::Index candidates) {
  synthetic::Normal normal(seed);
  EstimationProblem p;
  for (int run = 0; run < 2; ++run) {
    CovarianceTrack t;
    t.initial = spd(normal, n);
    for (int k = 0; k < 7 + run; ++k) {
      Eigen::MatrixXd f(n, n);
      for (Eigen::Index j = 0; j < n; ++j) f.col(j) = 0.3 * normal.vector(n);
      t.transitions.push_back(f + 0.6 * Eigen::MatrixXd::Identity(n, n));
      t.process.push_back(0.2 * spd(normal, n));
    }
    p.tracks.push_back(t);
  }
  p.candidate_rows.resize(candidates, n);
  for (Eigen::Index c = 0; c < candidates; ++c) p.candidate_rows.row(c) = normal.vector(n);
  p.candidate_sigma = 0.2 + 0.8 * normal.vector(candidates).cwiseAbs().array();
  p.target_rows.resize(2, n);
  p.target_rows.row(0) = normal.vector(n);
  p.target_rows.row(1) = normal.vector(n);
  return p;
}

TEST(Estimation, RankOneUpdatesEqualOneFreshUpdate) {
  synthetic::Normal normal(3);
  const Eigen::Index n = 9, m = 4;
  const Eigen::MatrixXd p = spd(normal, n);
  Eigen::MatrixXd h(m, n);
  for (Eigen::Index i = 0; i < m; ++i) h.row(i) = normal.vector(n);
  const Eigen::VectorXd r2 = (0.1 + normal.vector(m).cwiseAbs().array()).matrix();
  Eigen::MatrixXd sequential = p;
  for (Eigen::Index i = 0; i < m; ++i)
    sequential = updated_covariance(sequential, h.row(i).transpose(), r2(i));
  // P - P H^T (H P H^T + R)^-1 H P with an explicit inverse: another computation altogether.
  Eigen::MatrixXd s = h * p * h.transpose();
  s.diagonal() += r2;
  const Eigen::MatrixXd fresh = p - p * h.transpose() * s.inverse() * h * p;
  EXPECT_LE((sequential - fresh).cwiseAbs().maxCoeff(), 1e-10 * p.cwiseAbs().maxCoeff());
}

TEST(Estimation, TheGreedyCriterionIsTheSetsCriterion) {
  // The greedy runs the filter with rank-one updates per sensor; mean_posterior_variance updates
  // by all readings at once through a Cholesky factor. Each step's figure is the prefix's.
  const EstimationProblem p = random_problem(5, 8, 12);
  validate(p, 12, 2);
  std::vector<int> pool(12);
  for (int c = 0; c < 12; ++c) pool[static_cast<std::size_t>(c)] = c;
  const std::vector<int> both{0, 1};
  const GreedyPath path = estimation_greedy(p, pool, 5, both);
  ASSERT_EQ(path.order.size(), 5u);
  const Eigen::VectorXd none = mean_posterior_variance(p, {});
  double before = none.sum();
  for (std::size_t m = 1; m <= path.order.size(); ++m) {
    const std::vector<int> prefix(path.order.begin(),
                                  path.order.begin() + static_cast<std::ptrdiff_t>(m));
    const double fresh = mean_posterior_variance(p, prefix).sum();
    EXPECT_NEAR(path.scores[m - 1], fresh, 1e-10 * fresh) << "m = " << m;
    EXPECT_LT(fresh, before) << "m = " << m;  // every sensor added lowers it
    before = fresh;
  }
  // Its first choice is the best single sensor by the one-step score: here also the best by the
  // full criterion (every candidate checked afresh).
  double best = std::numeric_limits<double>::infinity();
  int best_c = -1;
  for (int c = 0; c < 12; ++c) {
    const double v = mean_posterior_variance(p, std::vector<int>{c}).sum();
    if (v < best) best = v, best_c = c;
  }
  EXPECT_EQ(path.order[0], best_c);
}

TEST(Estimation, TheGreedyTakesTheObviouslyInformativeSensor) {
  // Three independent random walks; the target is x0 + x1. Candidates: x0, x1, x2, x0 + x1 read
  // badly (sigma 5), x0 + x1 read well (sigma 0.1), and a row of zeros. The well-read sum is the
  // one sensor that sees the target whole; the zero row is never taken.
  EstimationProblem p;
  CovarianceTrack t;
  t.initial = Eigen::Matrix3d::Identity();
  t.transitions.assign(10, Eigen::Matrix3d::Identity());
  t.process.assign(10, 0.1 * Eigen::Matrix3d::Identity());
  p.tracks.push_back(t);
  p.candidate_rows.resize(6, 3);
  p.candidate_rows << 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 0, 1, 1, 0, 0, 0, 0;
  p.candidate_sigma.resize(6);
  p.candidate_sigma << 0.1, 0.1, 0.1, 5.0, 0.1, 0.1;
  p.target_rows.resize(2, 3);
  p.target_rows << 1, 1, 0, 0, 0, 1;
  const std::vector<int> pool{0, 1, 2, 3, 4, 5};
  const std::vector<int> sum{0}, third{1};
  EXPECT_EQ(estimation_greedy(p, pool, 1, sum).order, std::vector<int>{4});
  EXPECT_EQ(estimation_greedy(p, pool, 1, third).order, std::vector<int>{2});
  // Then the other readings of x0 and x1, and it stops: neither the third walk's sensor nor the
  // zero row lowers the variance of x0 + x1.
  const GreedyPath all = estimation_greedy(p, pool, 6, sum);
  ASSERT_EQ(all.order.size(), 4u);
  EXPECT_EQ(all.order[0], 4);
  for (int c : all.order) EXPECT_TRUE(c != 2 && c != 5) << c;
  // A veto takes the best admissible one.
  const auto no_sum = [](std::span<const int>, int c) { return c != 4; };
  const GreedyPath vetoed = estimation_greedy(p, pool, 1, sum, no_sum);
  ASSERT_EQ(vetoed.order.size(), 1u);
  EXPECT_NE(vetoed.order[0], 4);
  // A sensor of the third walk does nothing for x0 + x1: with the sum's sensors gone, x0 or x1.
  EXPECT_TRUE(vetoed.order[0] == 0 || vetoed.order[0] == 1);
}

TEST(Estimation, PlaceAllCarriesTheMethodAndChecksTheProblem) {
  auto input = synthetic::c54_input(0.05, 4);
  PlacementOptions options;
  options.methods = {Method::kObserverVariance, Method::kCorrelation};
  options.m_max = 3;
  // Without the observer's model the method is skipped.
  EXPECT_EQ(place_all(input, options).targets[0].selections.size(), 3u);
  input.estimation = synthetic::c54_estimation(input, 0.05, 20);
  const PlacementResult r = place_all(input, options);
  for (const auto& t : r.targets) {
    std::vector<Selection> by_variance;
    for (const auto& s : t.selections)
      if (s.method == Method::kObserverVariance) by_variance.push_back(s);
    ASSERT_EQ(by_variance.size(), 3u) << t.target;
    for (std::size_t m = 1; m < by_variance.size(); ++m) {
      EXPECT_EQ(by_variance[m].score_kind, "posterior_sigma_m");
      EXPECT_LT(by_variance[m].score, by_variance[m - 1].score) << t.target;
      EXPECT_TRUE(std::equal(by_variance[m - 1].columns.begin(), by_variance[m - 1].columns.end(),
                             by_variance[m].columns.begin()));
    }
    const int target = t.target == "dy" ? 0 : 1;
    const double fresh =
        mean_posterior_variance(*input.estimation, by_variance.back().columns)(target);
    EXPECT_NEAR(by_variance.back().score, std::sqrt(fresh), 1e-10 * std::sqrt(fresh));
    for (int c : by_variance.back().columns)  // the mirror rule: from the pool only
      EXPECT_NE(std::find(r.pool.begin(), r.pool.end(), c), r.pool.end());
  }
  auto wrong = input;
  wrong.estimation->candidate_rows.conservativeResize(53, Eigen::NoChange);
  EXPECT_THROW(place_all(wrong, options), core::DataError);
  wrong = input;
  wrong.estimation->candidate_sigma(7) = 0;
  EXPECT_THROW(place_all(wrong, options), core::DataError);
  wrong = input;
  wrong.estimation->tracks[0].process.pop_back();
  EXPECT_THROW(place_all(wrong, options), core::DataError);
}

}  // namespace
}  // namespace tt::placement
