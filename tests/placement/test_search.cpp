#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <set>

#include "core/errors.hpp"
#include "placement/gaussian.hpp"
#include "placement/search.hpp"
#include "synthetic.hpp"

using namespace tt::placement;

TEST(Search, CombinationCount) {
  EXPECT_EQ(combination_count(54, 3), 24804);
  EXPECT_EQ(combination_count(54, 1), 54);
  EXPECT_EQ(combination_count(5, 6), 0);
  EXPECT_EQ(combination_count(40, 20), std::int64_t{137846528820});
  EXPECT_EQ(combination_count(4000, 6), std::int64_t{5667585757783866000});
  EXPECT_EQ(combination_count(4000, 7), std::numeric_limits<std::int64_t>::max());
}

TEST(Search, ExhaustiveFindsTheBestAndBreaksTiesTowardsTheFirstCombination) {
  // Fitness: sum of weights, with two equal best combinations {1,3} and {2,3}.
  const std::vector<double> w = {0.1, 0.5, 0.5, 0.9, 0.2};
  const SetFitness f = [&](std::span<const int> s) {
    double v = 0.0;
    for (int i : s) v += w[static_cast<std::size_t>(i)];
    return v;
  };
  const auto r = exhaustive_search(5, 2, f);
  EXPECT_EQ(r.best, (std::vector<int>{1, 3}));
  EXPECT_DOUBLE_EQ(r.fitness, 1.4);
  EXPECT_EQ(r.evaluations, 10);
  EXPECT_THROW(exhaustive_search(5, 6, f), tt::core::DataError);
}

TEST(Search,
     GeneticSearchFindsTheExhaustiveOptimumInNinetyPercentOfSeedsWithFivePercentOfEvaluations) {
  // 54 candidates sharing a common drift (pairwise r ≈ 0.6); the error is a combination of three
  // of them, so the Gaussian fitness has a unique optimum that the best singles do not reveal.
  synthetic::Normal normal(77);
  const int samples = 100, n = 54;
  const Eigen::VectorXd drift = normal.vector(samples);
  Eigen::MatrixXd t(samples, n);
  for (int c = 0; c < n; ++c) t.col(c) = drift + 0.8 * normal.vector(samples);
  const Eigen::VectorXd y =
      t.col(7) + 0.7 * t.col(23) - 0.9 * t.col(41) + 0.3 * normal.vector(samples);
  const auto lp = linear_problem(t, y);
  const Collinearity guard;
  std::atomic<long> calls{0};
  const SetFitness fitness = [&](std::span<const int> s) {
    ++calls;
    const auto r2 = set_r_squared(lp, s, guard);
    return r2 ? gaussian_mi_bits(*r2) : -std::numeric_limits<double>::infinity();
  };

  const auto exhaustive = exhaustive_search(n, 3, fitness);
  ASSERT_EQ(exhaustive.best, (std::vector<int>{7, 23, 41}));
  // Unique: the runner-up is clearly worse.
  double second = -INFINITY;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      for (int c = b + 1; c < n; ++c) {
        const int s[3] = {a, b, c};
        if (std::vector<int>(s, s + 3) != exhaustive.best) second = std::max(second, fitness(s));
      }
  ASSERT_LT(second, exhaustive.fitness - 0.1);

  int found = 0;
  std::int64_t most = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    GaOptions options;
    options.seed = seed;
    calls = 0;
    const auto ga = genetic_search(n, 3, fitness, options);
    EXPECT_EQ(ga.evaluations, calls.load()) << "each distinct combination is evaluated once";
    most = std::max(most, ga.evaluations);
    found += ga.best == exhaustive.best;
  }
  RecordProperty("ga_success_of_20", found);
  RecordProperty("ga_most_evaluations", static_cast<int>(most));
  EXPECT_GE(found, 18);
  EXPECT_LE(most, 24804 / 20);  // at most 5 % of C(54, 3)
}

TEST(Search, GeneticSearchIsReproducibleAndRespectsInadmissibleCombinations) {
  // Candidates 0 and 1 are twins: any combination with both is inadmissible.
  const SetFitness f = [](std::span<const int> s) {
    std::set<int> m(s.begin(), s.end());
    if (m.count(0) && m.count(1)) return -std::numeric_limits<double>::infinity();
    double v = 0.0;
    for (int i : s) v += (i <= 1 ? 10.0 : 1.0 / (1.0 + i));
    return v;
  };
  GaOptions o;
  o.seed = 9;
  const auto a = genetic_search(30, 3, f, o);
  const auto b = genetic_search(30, 3, f, o);
  EXPECT_EQ(a.best, b.best);
  EXPECT_EQ(a.evaluations, b.evaluations);
  EXPECT_FALSE(a.best[0] == 0 && a.best[1] == 1);
  EXPECT_TRUE(std::isfinite(a.fitness));
}

TEST(Search, GeneticSearchStartsFromTheFallbackOnlyWhenNoRandomCombinationIsAdmissible) {
  // 2000 candidates of which only the first 12 mix: a 6-set is admissible only inside them (as
  // when almost every random set of smooth surface histories holds a collinear pair).
  const SetFitness f = [](std::span<const int> s) {
    double v = 0.0;
    for (int i : s) {
      if (i >= 12) return -std::numeric_limits<double>::infinity();
      v += 1.0 / (1.0 + i);
    }
    return v;
  };
  GaOptions o;
  o.seed = 4;
  const auto alone = genetic_search(2000, 6, f, o);
  EXPECT_FALSE(std::isfinite(alone.fitness)) << "the random start never finds an admissible set";
  const auto seeded = genetic_search(2000, 6, f, o, {{11, 3, 5, 7, 9, 10}});
  ASSERT_TRUE(std::isfinite(seeded.fitness));
  EXPECT_GE(seeded.fitness, f(std::vector<int>{3, 5, 7, 9, 10, 11}));
  for (int i : seeded.best) EXPECT_LT(i, 12);

  // When the random start has admissible members the fallback is not used: the same result.
  const SetFitness g = [](std::span<const int> s) {
    double v = 0.0;
    for (int i : s) v += std::sin(0.37 * i);
    return v;
  };
  const auto plain = genetic_search(2000, 6, g, o);
  const auto with_fallback = genetic_search(2000, 6, g, o, {{0, 1, 2, 3, 4, 5}});
  EXPECT_EQ(plain.best, with_fallback.best);
  EXPECT_EQ(plain.evaluations, with_fallback.evaluations);
  EXPECT_THROW(genetic_search(2000, 6, f, o, {{1, 1, 2, 3, 4, 5}}), tt::core::DataError);
}
