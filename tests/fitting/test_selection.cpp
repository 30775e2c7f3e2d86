// The selection protocol: choices made on validation groups only, then tested.
#include <gtest/gtest.h>
#include <omp.h>

#include <random>

#include "core/errors.hpp"
#include "fitting/selection.hpp"
#include "tests/fitting/synthetic.hpp"

using namespace tt::fitting;
using tt::fitting::test::campaign;
using tt::fitting::test::increment;

namespace {

constexpr double um = 1e-6;

std::vector<ModelSpec> few_specs() {
  std::vector<ModelSpec> specs(4);
  specs[1].kind = ModelKind::ridge;
  specs[1].ridge_lambda = 1e-2;
  specs[2].kind = ModelKind::projection_pursuit;
  specs[2].ppr.max_terms = 2;
  specs[3].kind = ModelKind::distributed_lag;
  specs[3].time_constants = {1800.0};
  specs[3].ridge_lambda = 1e-6;
  return specs;
}

Eigen::VectorXd lagged_truth(const Group& g) {
  return 1.5 * um * low_pass(g.time, increment(g, 0), 2400.0).array() +
         0.5 * um * increment(g, 3).array();
}

}  // namespace

TEST(Selection, NeverTouchesTestGroups) {
  const auto groups = campaign(6, 71, lagged_truth, 0.3 * um);
  const Split split{{0, 1, 2}, {3}, {4, 5}};
  std::vector<SensorSet> sets = correlation_sensor_sets(group_subset(groups, split.fitting), 0, 3);
  sets.push_back(SensorSet{"manual", {0, 3}});
  const Evaluation honest = evaluation(groups, split, 0, sets, few_specs());

  // Replace the test runs by garbage: if anything before testing read them, the choice changes.
  auto poisoned = groups;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uniform(-50.0, 50.0);
  for (int g : split.test) {
    for (Eigen::Index i = 0; i < poisoned[g].temperature.size(); ++i)
      poisoned[g].temperature(i) = 300.0 + uniform(rng);
    for (Eigen::Index i = 0; i < poisoned[g].error.size(); ++i)
      poisoned[g].error(i) = uniform(rng) * um;
  }
  const Evaluation blind = evaluation(poisoned, split, 0, sets, few_specs());

  ASSERT_EQ(honest.selection.candidates.size(), sets.size() * 4);
  EXPECT_EQ(honest.selection.best, blind.selection.best);
  for (std::size_t i = 0; i < honest.selection.candidates.size(); ++i)
    EXPECT_EQ(honest.selection.candidates[i].validation.sm,
              blind.selection.candidates[i].validation.sm);
  const auto& a = honest.model;
  const auto& b = blind.model;
  ASSERT_EQ(a.body.index(), b.body.index());
  if (const auto* la = std::get_if<LinearFit>(&a.body)) {
    EXPECT_EQ(la->coefficients, std::get<LinearFit>(b.body).coefficients);
    EXPECT_EQ(la->intercept, std::get<LinearFit>(b.body).intercept);
  }
  EXPECT_GT(blind.test.sm, 10.0 * honest.test.sm);

  // The refit uses fitting + validation groups, and the reported test S is the model's on them.
  EXPECT_EQ(honest.model.fitted_on, (std::vector<std::string>{"run0", "run1", "run2", "run3"}));
  const Accuracy recomputed = model_accuracy(honest.model, group_subset(groups, split.test));
  EXPECT_EQ(recomputed.s, honest.test.s);
  const double best_sm =
      honest.selection.candidates[static_cast<std::size_t>(honest.selection.best)].validation.sm;
  for (const auto& c : honest.selection.candidates) {
    if (c.model) {
      EXPECT_GE(c.validation.sm, best_sm);
    }
  }
  EXPECT_EQ(honest.test_groups, (std::vector<std::string>{"run4", "run5"}));
}

TEST(Selection, PicksTheDynamicModelForALaggedTarget) {
  const auto groups = campaign(6, 72, lagged_truth, 0.3 * um);
  const Split split{{0, 1, 2}, {3}, {4, 5}};
  const Evaluation e =
      evaluation(groups, split, 0, {SensorSet{"manual", {0, 3}}}, default_model_candidates());
  EXPECT_EQ(e.model.spec.kind, ModelKind::distributed_lag) << model_label(e.model.spec);
  std::printf("lagged target: chose %s, test SM %.3f um, S_sigma %.3f um\n",
              model_label(e.model.spec).c_str(), e.test.sm / um, e.test.s_sigma / um);
  EXPECT_LT(e.test.sm, 0.6 * um);
}

TEST(Selection, DoesNotDependOnTheThreadCount) {
  const auto groups = campaign(5, 73, lagged_truth, 0.3 * um);
  const Split split{{0, 1, 2}, {3}, {4}};
  const std::vector<SensorSet> sets{{"a", {0}}, {"a", {0, 3}}};
  omp_set_num_threads(1);
  const Selection one =
      selection_on_validation(group_subset(groups, split.fitting),
                              group_subset(groups, split.validation), 0, sets, few_specs());
  omp_set_num_threads(2);
  const Selection two =
      selection_on_validation(group_subset(groups, split.fitting),
                              group_subset(groups, split.validation), 0, sets, few_specs());
  ASSERT_EQ(one.candidates.size(), two.candidates.size());
  EXPECT_EQ(one.best, two.best);
  for (std::size_t i = 0; i < one.candidates.size(); ++i)
    EXPECT_EQ(one.candidates[i].validation.s, two.candidates[i].validation.s) << i;
}

TEST(Selection, LeaveOneGroupOutTestsEveryGroupOnce) {
  auto truth = [](const Group& g) {
    return Eigen::VectorXd(2.0 * um * increment(g, 0).array() - um * increment(g, 2).array());
  };
  const auto groups = campaign(4, 74, truth, 0.4 * um);
  const LeaveOneGroupOut logo = leave_one_group_out(groups, 0, {{"m", {0, 2}}}, {ModelSpec{}});
  ASSERT_EQ(logo.folds.size(), 4u);
  ASSERT_EQ(logo.test.s.size(), 4u);
  for (int g = 0; g < 4; ++g) {
    EXPECT_EQ(logo.folds[g].test_groups, std::vector<std::string>{groups[g].name});
    std::vector<Group> others;
    for (int o = 0; o < 4; ++o)
      if (o != g) others.push_back(groups[o]);
    // Validation group is refitted in, so the fold's model is fitted on all other groups.
    const FittedModel manual = fitted_model(ModelSpec{}, others, {0, 2}, 0);
    const double s = residual_std(groups[g].error.col(0) - predicted_error(manual, groups[g]));
    EXPECT_NEAR(logo.test.s[g], s, 1e-12 * um);
  }
  EXPECT_NEAR(logo.test.sm / (0.4 * um), 1.0, 0.15);
  EXPECT_THROW(leave_one_group_out({groups[0], groups[1]}, 0, {{"m", {0}}}, {ModelSpec{}}),
               tt::core::DataError);
}

TEST(Selection, SensorCountTableFindsTheSmallestSufficientM) {
  // The error needs three sensors; two cannot reach 0.6 µm.
  auto truth = [](const Group& g) {
    return Eigen::VectorXd(2.0 * um * increment(g, 0).array() - 1.5 * um * increment(g, 3).array() +
                           1.0 * um * increment(g, 5).array());
  };
  const auto groups = campaign(6, 75, truth, 0.3 * um);
  const Split split{{0, 1, 2}, {3}, {4, 5}};
  const std::vector<SensorSet> sets{{"a", {0}},          {"a", {0, 3}}, {"a", {0, 3, 5}},
                                    {"a", {0, 3, 5, 1}}, {"b", {1}},    {"b", {1, 2}}};
  std::vector<ModelSpec> specs(2);
  specs[1].kind = ModelKind::ridge;
  specs[1].ridge_lambda = 1e-3;
  const SensorCountTable table = sensor_count_table(groups, split, 0, sets, specs, 0.6 * um);
  ASSERT_EQ(table.rows.size(), 6u);
  for (const auto& r : table.rows)
    std::printf("%s m=%d %s validation SM %.3f test SM %.3f S_sigma %.3f um\n", r.method.c_str(),
                r.m, r.model.c_str(), r.validation_sm / um, r.test_sm / um, r.test_s_sigma / um);
  ASSERT_TRUE(table.smallest_m_validation.count("a"));
  EXPECT_EQ(table.smallest_m_validation.at("a"), 3);
  EXPECT_EQ(table.smallest_m_test.at("a"), 3);
  EXPECT_FALSE(table.smallest_m_validation.count("b"));
  EXPECT_LT(table.rows[2].test_sm, 0.4 * um);
  EXPECT_GT(table.rows[1].test_sm, 0.6 * um);
}

TEST(Selection, RejectsInconsistentSplits) {
  auto truth = [](const Group& g) { return Eigen::VectorXd(um * increment(g, 0)); };
  const auto groups = campaign(4, 76, truth, 0.1 * um);
  const std::vector<SensorSet> one_set{{"m", {0}}};
  EXPECT_THROW(evaluation(groups, Split{{0, 1}, {1}, {2}}, 0, one_set, {ModelSpec{}}),
               tt::core::DataError);
  EXPECT_THROW(evaluation(groups, Split{{0, 1}, {}, {2}}, 0, one_set, few_specs()),
               tt::core::DataError);
  EXPECT_THROW(evaluation(groups, Split{{0, 9}, {2}, {3}}, 0, one_set, {ModelSpec{}}),
               tt::core::DataError);
  // A single candidate needs no validation group.
  const Evaluation e = evaluation(groups, Split{{0, 1}, {}, {2, 3}}, 0, one_set, {ModelSpec{}});
  EXPECT_EQ(e.test.s.size(), 2u);
}
