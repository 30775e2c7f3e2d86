// The standard's metrics, the increments and the filters the models are built on.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/errors.hpp"
#include "fitting/features.hpp"
#include "fitting/linear.hpp"
#include "fitting/metrics.hpp"
#include "tests/fitting/synthetic.hpp"

using namespace tt::fitting;

TEST(Metrics, ReproduceTheWorkedExampleOfFormulasMd) {
  const double s1 = residual_std(Eigen::Vector4d(-0.1, 0.1, -0.2, 0.2));
  const double s2 = residual_std(Eigen::Vector4d(0.3, -0.3, 0.0, 0.0));
  EXPECT_NEAR(s1, 0.182574, 1e-6);
  EXPECT_NEAR(s2, 0.244949, 1e-6);
  const Accuracy a = accuracy({s1, s2});
  EXPECT_NEAR(a.sm, 0.213762, 1e-6);
  EXPECT_NEAR(a.s_sigma, 0.044106, 1e-6);
  ASSERT_EQ(a.s.size(), 2u);
}

TEST(Metrics, SingleGroupHasNoRobustnessAndTooFewReadingsThrow) {
  const Accuracy a = accuracy({0.5});
  EXPECT_DOUBLE_EQ(a.sm, 0.5);
  EXPECT_TRUE(std::isnan(a.s_sigma));
  EXPECT_THROW(residual_std(Eigen::VectorXd::Ones(1)), tt::core::DataError);
  EXPECT_THROW(accuracy({}), tt::core::DataError);
}

TEST(Features, LowPassIsExactForARampOnANonUniformGrid) {
  const double tau = 700.0;
  Eigen::VectorXd t(7);
  t << 0.0, 10.0, 250.0, 260.0, 1000.0, 3000.0, 3001.0;
  const Eigen::VectorXd y = low_pass(t, 2.0 * t, tau);
  for (Eigen::Index i = 0; i < t.size(); ++i)
    EXPECT_NEAR(y(i), 2.0 * (t(i) - tau * (1.0 - std::exp(-t(i) / tau))), 1e-9) << i;
  EXPECT_THROW(low_pass(t, t, 0.0), tt::core::DataError);
}

TEST(Features, IncrementsAreRelativeToEachGroupsOwnFirstReading) {
  Group g = test::thermal_run(0, 5, 3);
  const Eigen::MatrixXd d = temperature_increments(g, {2, 0});
  EXPECT_EQ(d.cols(), 2);
  EXPECT_DOUBLE_EQ(d(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(d(10, 1), g.temperature(10, 0) - g.temperature(0, 0));
  FeatureMap map{{2, 0}, {"t3", "t1"}, {1800.0}};
  const Eigen::MatrixXd f = feature_matrix(map, g);
  EXPECT_EQ(f.cols(), 4);
  EXPECT_EQ(feature_names(map)[3], "lp1800s(dT[t1])");
  EXPECT_TRUE(f.col(3).isApprox(low_pass(g.time, d.col(1), 1800.0)));
}

TEST(Linear, LeastSquaresIsTheStandardsNormalEquations) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd x(40, 3);
  Eigen::VectorXd e(40);
  for (int i = 0; i < 40; ++i) {
    for (int k = 0; k < 3; ++k) x(i, k) = normal(rng);
    e(i) = normal(rng);
  }
  Eigen::MatrixXd a(40, 4);
  a << Eigen::VectorXd::Ones(40), x;
  const Eigen::VectorXd beta = (a.transpose() * a).inverse() * a.transpose() * e;  // formula 4
  const LinearFit fit = linear_fit(x, e, 0.0);
  EXPECT_NEAR(fit.intercept, beta(0), 1e-12);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(fit.coefficients(k), beta(k + 1), 1e-12);
}

TEST(Linear, RidgeShrinksSlopesButNotTheIntercept) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd x(60, 2);
  Eigen::VectorXd y(60);
  for (int i = 0; i < 60; ++i) {
    x(i, 0) = normal(rng);
    x(i, 1) = x(i, 0) + 0.05 * normal(rng);
    y(i) = 5.0 + 2.0 * x(i, 0) + 0.1 * normal(rng);
  }
  const LinearFit ls = linear_fit(x, y, 0.0);
  const LinearFit tiny = linear_fit(x, y, 1e-12);
  EXPECT_LT((ls.coefficients - tiny.coefficients).norm(), 1e-6);
  double previous = ls.coefficients.norm();
  for (double lambda : {1e-3, 1e-1, 10.0}) {
    const double norm = linear_fit(x, y, lambda).coefficients.norm();
    EXPECT_LT(norm, previous) << lambda;
    previous = norm;
  }
  const LinearFit huge = linear_fit(x, y, 1e9);
  EXPECT_NEAR(huge.intercept, y.mean(), 1e-6);
  EXPECT_THROW(linear_fit(x, y, -1.0), tt::core::DataError);
}
