// The models on synthetic runs whose truth is known: each test can fail if a model is wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "core/errors.hpp"
#include "fitting/models.hpp"
#include "tests/fitting/synthetic.hpp"

using namespace tt::fitting;
using tt::fitting::test::campaign;
using tt::fitting::test::increment;

namespace {

constexpr double um = 1e-6;

/// 3 µm + 2 µm/K·ΔT1 − 1.5 µm/K·ΔT3
Eigen::VectorXd linear_truth(const Group& g) {
  return (3.0 * um + 2.0 * um * increment(g, 0).array() - 1.5 * um * increment(g, 2).array())
      .matrix();
}

std::vector<Group> first(const std::vector<Group>& groups, int count) {
  return {groups.begin(), groups.begin() + count};
}
std::vector<Group> last(const std::vector<Group>& groups, int count) {
  return {groups.end() - count, groups.end()};
}

/// Standard errors of [β0, β...] from σ²(AᵀA)⁻¹ on the stacked fitting rows.
Eigen::VectorXd standard_errors(const std::vector<Group>& groups, const std::vector<int>& sensors,
                                double sigma) {
  FeatureMap map{sensors, {}, {}, {}, {}};
  for (int s : sensors) map.sensor_names.push_back(groups[0].sensor_names[s]);
  const StackedRows rows = stacked_rows(map, groups, 0);
  Eigen::MatrixXd a(rows.features.rows(), rows.features.cols() + 1);
  a << Eigen::VectorXd::Ones(rows.features.rows()), rows.features;
  return (sigma * sigma * (a.transpose() * a).inverse()).diagonal().cwiseSqrt();
}

}  // namespace

TEST(LeastSquares, RecoversCoefficientsAndSMatchesTheNoise) {
  const double sigma = 0.5 * um;
  const auto groups = campaign(6, 11, linear_truth, sigma, 6, 30.0);
  const FittedModel model = fitted_model(ModelSpec{}, first(groups, 4), {0, 2}, 0);
  const auto& fit = std::get<LinearFit>(model.body);
  const Eigen::VectorXd se = standard_errors(first(groups, 4), {0, 2}, sigma);
  EXPECT_NEAR(fit.intercept, 3.0 * um, 4.0 * se(0));
  EXPECT_NEAR(fit.coefficients(0), 2.0 * um, 4.0 * se(1));
  EXPECT_NEAR(fit.coefficients(1), -1.5 * um, 4.0 * se(2));
  const Accuracy test = model_accuracy(model, last(groups, 2));
  std::printf(
      "linear target: beta0 %+.4f beta1 %+.4f beta3 %+.4f um(/K) (se %.4f %.4f %.4f), "
      "test SM/sigma %.3f, rejected %d of %d\n",
      fit.intercept / um - 3.0, fit.coefficients(0) / um - 2.0, fit.coefficients(1) / um + 1.5,
      se(0) / um, se(1) / um, se(2) / um, test.sm / sigma, model.rejection.rejected,
      model.rejection.samples);
  EXPECT_NEAR(test.sm / sigma, 1.0, 0.1);
  for (double s : test.s) EXPECT_NEAR(s / sigma, 1.0, 0.1);
  EXPECT_EQ(model.fitted_on.size(), 4u);
  EXPECT_EQ(model.features.sensor_names, (std::vector<std::string>{"t1", "t3"}));
}

TEST(LeastSquares, ThreeSigmaRejectionRemovesInjectedGrossErrors) {
  const double sigma = 0.5 * um;
  auto groups = campaign(6, 12, linear_truth, sigma, 6, 30.0);
  // Ten gross errors of 15 to 25 σ in the fitting groups, e.g. a probe knocked during a run.
  std::mt19937_64 rng(99);
  std::set<int> injected;
  const int n = static_cast<int>(groups[0].time.size());
  while (injected.size() < 10) injected.insert(static_cast<int>(rng() % (4 * n)));
  for (int row : injected) {
    const double size = (15.0 + 10.0 * static_cast<double>(rng() % 1000) / 1000.0) * sigma;
    groups[row / n].error(row % n, 0) += (row % 2 ? size : -size);
  }
  const FittedModel with = fitted_model(ModelSpec{}, first(groups, 4), {0, 2}, 0);
  ModelSpec plain;
  plain.reject_gross_errors = false;
  const FittedModel without = fitted_model(plain, first(groups, 4), {0, 2}, 0);

  const std::set<int> rejected(with.rejection.rejected_rows.begin(),
                               with.rejection.rejected_rows.end());
  for (int row : injected)
    EXPECT_TRUE(rejected.count(row)) << "gross error at row " << row << " kept";
  EXPECT_LE(with.rejection.rejected, 10 + static_cast<int>(0.02 * 4 * n));
  EXPECT_GE(with.rejection.passes, 2);
  EXPECT_EQ(without.rejection.rejected, 0);

  const Eigen::VectorXd se = standard_errors(first(groups, 4), {0, 2}, sigma);
  const auto& a = std::get<LinearFit>(with.body);
  const auto& b = std::get<LinearFit>(without.body);
  EXPECT_NEAR(a.coefficients(0), 2.0 * um, 4.0 * se(1));
  EXPECT_NEAR(a.coefficients(1), -1.5 * um, 4.0 * se(2));
  std::printf(
      "gross errors: rejected %d of %d samples in %d passes; slope errors with %+.4f %+.4f, "
      "without %+.4f %+.4f um/K\n",
      with.rejection.rejected, with.rejection.samples, with.rejection.passes,
      a.coefficients(0) / um - 2.0, a.coefficients(1) / um + 1.5, b.coefficients(0) / um - 2.0,
      b.coefficients(1) / um + 1.5);
  const Eigen::Vector3d truth(3.0 * um, 2.0 * um, -1.5 * um);
  const Eigen::Vector3d with_beta(a.intercept, a.coefficients(0), a.coefficients(1));
  const Eigen::Vector3d without_beta(b.intercept, b.coefficients(0), b.coefficients(1));
  EXPECT_LT((with_beta - truth).norm(), (without_beta - truth).norm());
}

TEST(ProjectionPursuit, RecoversASingleCubicRidge) {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd x(300, 4);
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    for (Eigen::Index k = 0; k < 4; ++k) x(i, k) = normal(rng);
  const Eigen::Vector4d a = Eigen::Vector4d(0.6, -0.3, 0.0, 0.74).normalized();
  const Eigen::VectorXd z = x * a;
  const Eigen::VectorXd y = z.array().cube() + 0.5 * z.array();
  PprOptions options;
  options.max_terms = 2;
  const PprModel model = ppr_fit(x, y, options);
  ASSERT_GE(model.terms.size(), 1u);
  // The inputs are standardised, so compare the direction mapped back to raw inputs.
  const Eigen::VectorXd raw = model.terms[0].direction.cwiseQuotient(model.scale).normalized();
  EXPECT_GT(std::abs(raw.dot(a)), 0.999);
  const Eigen::VectorXd r = y - ppr_prediction(model, x);
  EXPECT_LT(r.norm() / (y.array() - y.mean()).matrix().norm(), 0.01);
  EXPECT_GE(model.terms[0].cluster_size, 1);
}

TEST(ProjectionPursuit, BeatsLeastSquaresOnANonlinearTarget) {
  // E = 10 µm · sin(1.5 u), u a projection of four temperature increments.
  auto truth = [](const Group& g) {
    const Eigen::ArrayXd u = (0.5 * increment(g, 0).array() + 0.3 * increment(g, 1).array() -
                              0.4 * increment(g, 3).array() + 0.6 * increment(g, 4).array()) /
                             5.0;
    return Eigen::VectorXd((10.0 * um * (1.5 * u).sin()).matrix());
  };
  const auto groups = campaign(9, 31, truth, 0.3 * um);
  const std::vector<int> sensors{0, 1, 3, 4};
  ModelSpec ppr;
  ppr.kind = ModelKind::projection_pursuit;
  ppr.ppr.degree = 4;
  ppr.ppr.max_terms = 3;
  const FittedModel p = fitted_model(ppr, first(groups, 6), sensors, 0);
  const FittedModel ls = fitted_model(ModelSpec{}, first(groups, 6), sensors, 0);
  const double ppr_sm = model_accuracy(p, last(groups, 3)).sm;
  const double ls_sm = model_accuracy(ls, last(groups, 3)).sm;
  std::printf("nonlinear target: test SM PPR %.3f um, least squares %.3f um\n", ppr_sm / um,
              ls_sm / um);
  EXPECT_LE(ppr_sm, 0.7 * ls_sm);
}

TEST(DistributedLag, BeatsAStaticModelOnALaggedTarget) {
  // The error follows the fast sensor t1 (τ = 300 s) through a 2400 s lag.
  auto truth = [](const Group& g) {
    return Eigen::VectorXd(1.5 * um * low_pass(g.time, increment(g, 0), 2400.0).array());
  };
  const auto groups = campaign(6, 41, truth, 0.3 * um);
  ModelSpec lag;
  lag.kind = ModelKind::distributed_lag;
  lag.time_constants = {900.0, 3600.0};
  lag.ridge_lambda = 1e-6;
  const FittedModel dynamic = fitted_model(lag, first(groups, 4), {0}, 0);
  const FittedModel stat = fitted_model(ModelSpec{}, first(groups, 4), {0}, 0);
  const double dynamic_sm = model_accuracy(dynamic, last(groups, 2)).sm;
  const double static_sm = model_accuracy(stat, last(groups, 2)).sm;
  std::printf("lagged target: test SM distributed lag %.3f um, static %.3f um\n", dynamic_sm / um,
              static_sm / um);
  EXPECT_LT(dynamic_sm, 0.5 * static_sm);
  EXPECT_EQ(std::get<LinearFit>(dynamic.body).coefficients.size(), 3);
}

TEST(VariableChoice, CorrelationRanksTheDrivingSensorFirst) {
  auto truth = [](const Group& g) { return Eigen::VectorXd(2.0 * um * increment(g, 2).array()); };
  const auto groups = campaign(3, 51, truth, 0.1 * um);
  const std::vector<int> ranked = sensors_by_correlation(groups, 0, 3);
  ASSERT_EQ(ranked.size(), 3u);
  EXPECT_EQ(ranked[0], 2);
  EXPECT_THROW(sensors_by_correlation(groups, 0, 7), tt::core::DataError);
}

TEST(Groups, MalformedGroupsThrowNamingTheGroup) {
  auto truth = [](const Group& g) { return Eigen::VectorXd(um * increment(g, 0)); };
  auto groups = campaign(2, 61, truth, 0.0);
  auto renamed = groups;
  renamed[1].sensor_names[0] = "other";
  try {
    require_consistent_groups(renamed);
    FAIL() << "no error for differing sensor names";
  } catch (const tt::core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("run1"), std::string::npos) << e.what();
  }
  auto backwards = groups;
  backwards[0].time(3) = backwards[0].time(2);
  EXPECT_THROW(require_consistent_groups(backwards), tt::core::DataError);
  auto holes = groups;
  holes[1].temperature(5, 2) = std::nan("");
  EXPECT_THROW(require_consistent_groups(holes), tt::core::DataError);
  EXPECT_THROW(fitted_model(ModelSpec{}, groups, {}, 0), tt::core::DataError);
  EXPECT_THROW(fitted_model(ModelSpec{}, groups, {0}, 3), tt::core::DataError);
  EXPECT_THROW(predicted_error(fitted_model(ModelSpec{}, groups, {0}, 0), renamed[1]),
               tt::core::DataError);
}
