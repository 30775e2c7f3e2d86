#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>

#include "placement/baselines.hpp"
#include "placement/gaussian.hpp"
#include "placement/qr_pod.hpp"
#include "placement/twins.hpp"
#include "synthetic.hpp"

using namespace tt::placement;

namespace {

/// R² of the least-squares fit with intercept, computed the textbook way.
double r_squared_by_lstsq(const Eigen::MatrixXd& t, const std::vector<int>& set,
                          const Eigen::VectorXd& y) {
  Eigen::MatrixXd a(t.rows(), set.size() + 1);
  a.col(0).setOnes();
  for (std::size_t k = 0; k < set.size(); ++k)
    a.col(static_cast<Eigen::Index>(k) + 1) = t.col(set[k]);
  const Eigen::VectorXd beta = a.colPivHouseholderQr().solve(y);
  const Eigen::VectorXd res = y - a * beta;
  return 1.0 - res.squaredNorm() / (y.array() - y.mean()).matrix().squaredNorm();
}

}  // namespace

TEST(Gaussian, SetRSquaredMatchesLeastSquaresAndMiFormula) {
  synthetic::Normal normal(31);
  Eigen::MatrixXd t(60, 5);
  for (int c = 0; c < 5; ++c)
    t.col(c) = normal.vector(60) * (c + 1.0) + Eigen::VectorXd::Constant(60, 20.0);
  const Eigen::VectorXd y = 2.0 * t.col(1) - t.col(3) + normal.vector(60);
  const auto lp = linear_problem(t, y);
  const std::vector<int> set = {3, 1, 4};
  const auto r2 = set_r_squared(lp, set, {});
  ASSERT_TRUE(r2.has_value());
  EXPECT_NEAR(*r2, r_squared_by_lstsq(t, set, y), 1e-12);
  EXPECT_NEAR(gaussian_mi_bits(0.81), 1.197964, 1e-6);
  EXPECT_TRUE(std::isfinite(gaussian_mi_bits(1.0)));
}

TEST(Gaussian, GreedyFollowsTheBestRSquaredAtEveryStep) {
  synthetic::Normal normal(32);
  Eigen::MatrixXd t(80, 12);
  for (int c = 0; c < 12; ++c) t.col(c) = normal.vector(80);
  const Eigen::VectorXd y = t.col(4) + 0.6 * t.col(9) + 0.3 * t.col(2) + 0.1 * normal.vector(80);
  const auto lp = linear_problem(t, y);
  std::vector<int> pool(12);
  std::iota(pool.begin(), pool.end(), 0);
  const auto path = gaussian_greedy(lp, pool, 4, {});
  ASSERT_EQ(path.order.size(), 4u);
  EXPECT_EQ(std::vector<int>(path.order.begin(), path.order.begin() + 3),
            (std::vector<int>{4, 9, 2}));
  for (std::size_t m = 1; m <= 4; ++m) {
    const std::vector<int> set(path.order.begin(),
                               path.order.begin() + static_cast<std::ptrdiff_t>(m));
    EXPECT_NEAR(path.scores[m - 1], gaussian_mi_bits(r_squared_by_lstsq(t, set, y)), 1e-9);
  }
}

TEST(Twins, CollinearCandidatesAreNotCountedAsTwoSensors) {
  synthetic::Normal normal(33);
  Eigen::MatrixXd t(50, 4);
  t.col(0) = normal.vector(50);
  t.col(1) = 2.0 * t.col(0) + 1e-4 * normal.vector(50);  // a twin: r > 0.999
  t.col(2) = normal.vector(50);
  t.col(3) = t.col(0) - 3.0 * t.col(2);  // lies in the span of 0 and 2
  const Eigen::VectorXd y = t.col(0) + 0.5 * t.col(2);
  const auto lp = linear_problem(t, y);
  const int c0[1] = {0};
  EXPECT_FALSE(adds_direction(lp, c0, 1, {}));
  EXPECT_TRUE(adds_direction(lp, c0, 2, {}));
  const int c02[2] = {0, 2};
  EXPECT_FALSE(adds_direction(lp, c02, 3, {}));
  const int twins[2] = {0, 1};
  EXPECT_FALSE(set_r_squared(lp, twins, {}).has_value());
  const auto path = gaussian_greedy(lp, std::vector<int>{0, 1, 2, 3}, 4, {});
  EXPECT_EQ(path.order.size(), 2u) << "after 0 and 2 nothing adds a direction";
}

TEST(Twins, MirrorPairsOfC54AndTheSearchPoolKeepTheLowerId) {
  const auto pairs = mirror_twins(synthetic::c54_positions(), 0.0, 1e-6);
  ASSERT_EQ(pairs.size(), 24u);                     // 6 on the top face, 18 between the side faces
  EXPECT_EQ(pairs.front(), std::make_pair(0, 2));   // ids 1 and 3: x = -0.08 and 0.08
  EXPECT_EQ(pairs.back(), std::make_pair(35, 53));  // ids 36 and 54
  for (const auto& [lo, hi] : pairs) EXPECT_LT(lo, hi);
  const auto pool = search_pool(54, pairs);
  EXPECT_EQ(pool.size(), 30u);
  EXPECT_EQ(pool[0], 0);
  EXPECT_EQ(pool[1], 1);
  EXPECT_EQ(pool[2], 3);
}

/// The definition, all pairs: for each i off the plane, the lowest j > i at its mirror image.
static std::vector<std::pair<int, int>> all_pairs_twins(const Eigen::MatrixX3d& x, double plane,
                                                        double tol) {
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < x.rows(); ++i) {
    if (std::abs(x(i, 0) - plane) <= tol) continue;
    Eigen::RowVector3d image = x.row(i);
    image(0) = 2 * plane - image(0);
    for (int j = i + 1; j < x.rows(); ++j)
      if ((x.row(j) - image).cwiseAbs().maxCoeff() <= tol) {
        pairs.emplace_back(i, j);
        break;
      }
  }
  return pairs;
}

TEST(Twins, ThousandsOfSurfaceVerticesGiveTheAllPairsAnswerFast) {
  // 6000 candidates on a box surface: 2000 mirrored pairs about x = 0.01 in shuffled order, some
  // images off by just more or just less than the tolerance, points on the plane, and a
  // point duplicated (its image then matches the lowest of the copies).
  std::mt19937_64 gen(5);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  const double plane = 0.01, tol = 1e-6;
  std::vector<Eigen::RowVector3d> pts;
  for (int k = 0; k < 2000; ++k) {
    const Eigen::RowVector3d a(plane + 0.001 + std::abs(u(gen)), u(gen),
                               std::round(u(gen) * 50) / 50);
    Eigen::RowVector3d b = a;
    b(0) = 2 * plane - a(0);
    if (k % 7 == 0) b(1) += (k % 2 ? 0.9 : 1.1) * tol;  // half within tolerance, half just outside
    pts.push_back(a);
    pts.push_back(b);
  }
  for (int k = 0; k < 1500; ++k) pts.emplace_back(u(gen), u(gen), u(gen));
  for (int k = 0; k < 400; ++k) pts.emplace_back(plane + (k % 3 - 1) * 0.5 * tol, u(gen), u(gen));
  for (int k = 0; k < 100; ++k) pts.push_back(pts[static_cast<std::size_t>(2 * k)]);
  std::shuffle(pts.begin(), pts.end(), gen);
  Eigen::MatrixX3d x(static_cast<Eigen::Index>(pts.size()), 3);
  for (std::size_t i = 0; i < pts.size(); ++i) x.row(static_cast<Eigen::Index>(i)) = pts[i];

  const auto start = std::chrono::steady_clock::now();
  const auto fast = mirror_twins(x, plane, tol);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto reference = all_pairs_twins(x, plane, tol);
  EXPECT_EQ(fast, reference);
  EXPECT_GT(fast.size(), 1900u);
  EXPECT_LT(seconds, 0.5) << "6000 candidates took " << seconds << " s";
}

TEST(QrPod, PivotsPickOneCandidatePerIndependentPattern) {
  // Three spatial patterns with distinct time signatures; candidates 5, 12 and 17 carry them
  // purely, the others are mixtures with smaller amplitude.
  synthetic::Normal normal(34);
  const int s = 40, n = 20;
  Eigen::MatrixXd f(s, 3);
  for (int a = 0; a < 3; ++a) f.col(a) = normal.vector(s);
  Eigen::MatrixXd w(3, n);
  for (int c = 0; c < n; ++c) w.col(c) = 0.2 * normal.vector(3);
  w.col(5) << 3.0, 0.0, 0.0;
  w.col(12) << 0.0, 2.0, 0.0;
  w.col(17) << 0.0, 0.0, 1.5;
  const Eigen::MatrixXd t = f * w;
  const auto modes = pod_modes(t, 3);
  ASSERT_EQ(modes.cols(), 3);
  EXPECT_EQ(pod_modes(t, 6).cols(), 3) << "rank 3 data has 3 modes";
  const Eigen::VectorXd y = t.col(0);
  const auto lp = linear_problem(t, y);
  std::vector<int> pool(n);
  std::iota(pool.begin(), pool.end(), 0);
  auto pivots = qr_pivots(modes, pool, 3, lp, {});
  std::sort(pivots.begin(), pivots.end());
  EXPECT_EQ(pivots, (std::vector<int>{5, 12, 17}));
  EXPECT_EQ(qr_pivots(modes, pool, 5, lp, {}).size(), 3u) << "modes exhausted after 3";
}

TEST(Baselines, GreyRelationalGradeOnAHandExample) {
  // z-scored: y = (−1, 0, 1); x0 = y exactly; x1 = (1, 0, −1). Δ0 = 0, Δ1 = (2, 0, 2).
  // Δmin = 0, Δmax = 2, ρ = 0.5: ξ0 = 1; ξ1 = (1/3, 1, 1/3) -> grade 5/9.
  Eigen::MatrixXd t(3, 2);
  t << 10, 7, 11, 6, 12, 5;
  Eigen::VectorXd y(3);
  y << 0.1, 0.2, 0.3;
  const auto g = grey_relational_grades(t, y, 0.5);
  EXPECT_NEAR(g(0), 1.0, 1e-12);
  EXPECT_NEAR(g(1), 5.0 / 9.0, 1e-12);
  const auto rank = ranks_descending(g);
  EXPECT_EQ(rank, (std::vector<int>{1, 2}));
  Eigen::VectorXd tie(3);
  tie << 0.5, 0.9, 0.5;
  EXPECT_EQ(ranks_descending(tie), (std::vector<int>{2, 1, 3})) << "ties: lower index first";
}
