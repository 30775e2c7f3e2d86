#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <set>

#include "core/errors.hpp"
#include "placement/place.hpp"
#include "placement/twins.hpp"
#include "synthetic.hpp"

using namespace tt::placement;

namespace {

PlacementOptions quick_options() {
  PlacementOptions o;
  o.m_max = 6;
  o.saturation.shuffles = 99;
  o.saturation.sampled_combinations = 50;
  return o;
}

void expect_no_twin_pair(const PlacementResult& r, const std::vector<std::pair<int, int>>& pairs) {
  for (const auto& t : r.targets)
    for (const auto& s : t.selections) {
      const std::set<int> chosen(s.columns.begin(), s.columns.end());
      EXPECT_EQ(chosen.size(), s.columns.size());
      for (const auto& [a, b] : pairs)
        EXPECT_FALSE(chosen.count(a) && chosen.count(b))
            << method_name(s.method) << " m = " << s.m << " chose twins " << a + 1 << " and "
            << b + 1 << " for " << t.target;
    }
}

}  // namespace

TEST(Place, TwinsAreNeverBothChosenWithOrWithoutTheMirrorRule) {
  auto input = synthetic::c54_input(0.002, 1);
  input.estimation = synthetic::c54_estimation(input, 0.05, 20);
  const auto pairs = mirror_twins(input.positions_m, 0.0, 1e-6);
  ASSERT_EQ(pairs.size(), 24u);

  auto options = quick_options();
  std::vector<std::string> lines;
  options.progress = [&](const std::string& line) { lines.push_back(line); };
  options.progress_after_s = 0;  // every method says when it is done
  const auto with_rule = place_all(input, options);
  EXPECT_EQ(with_rule.pool.size(), 30u);
  // A line per target and method as it is done (KSG and JMI share theirs), in the targets' order.
  ASSERT_EQ(lines.size(), with_rule.targets.size() * (all_methods().size() - 1));
  for (std::size_t t = 0; t < with_rule.targets.size(); ++t) {
    const std::string& first = lines[t * (all_methods().size() - 1)];
    EXPECT_EQ(first.rfind(with_rule.targets[t].target + ": histogram_mi, m = 1..6, ", 0), 0u)
        << first;
  }
  EXPECT_NE(lines.back().find("observer_variance"), std::string::npos) << lines.back();
  options.progress = {};
  expect_no_twin_pair(with_rule, pairs);

  // Without the declared mirror pairs only the correlation guard protects: twins differ by
  // 2 mK of noise, so they correlate above 0.999 and must still not be chosen together.
  options.mirror_twins = false;
  const auto by_correlation = place_all(input, options);
  EXPECT_EQ(by_correlation.pool.size(), 54u);
  expect_no_twin_pair(by_correlation, pairs);

  // Every method gave sets, each method m = 1 upwards.
  for (const auto& t : with_rule.targets) {
    std::set<std::string_view> methods;
    for (const auto& s : t.selections) methods.insert(method_name(s.method));
    EXPECT_EQ(methods.size(), all_methods().size()) << t.target;
  }
}

TEST(Place, ResultsDoNotDependOnTheThreadCount) {
  const auto input = synthetic::c54_input(0.05, 2);
  auto options = quick_options();
  options.exhaustive_limit = 2000;    // force the genetic search from m = 3 on
  options.ga.min_parallel_batch = 1;  // and evaluate every generation in parallel
  omp_set_num_threads(1);
  const auto one = place_all(input, options);
  omp_set_num_threads(2);
  const auto two = place_all(input, options);
  ASSERT_EQ(one.targets.size(), two.targets.size());
  bool used_ga = false;
  for (std::size_t t = 0; t < one.targets.size(); ++t) {
    const auto& a = one.targets[t];
    const auto& b = two.targets[t];
    EXPECT_TRUE((a.mi_bits.array() == b.mi_bits.array()).all());
    ASSERT_EQ(a.selections.size(), b.selections.size());
    for (std::size_t k = 0; k < a.selections.size(); ++k) {
      const auto& sa = a.selections[k];
      const auto& sb = b.selections[k];
      used_ga = used_ga || sa.search == "ga";
      EXPECT_EQ(sa.columns, sb.columns) << method_name(sa.method) << " m = " << sa.m;
      EXPECT_EQ(std::memcmp(&sa.score, &sb.score, sizeof(double)), 0) << method_name(sa.method);
      EXPECT_EQ(std::memcmp(&sa.gaussian_bits, &sb.gaussian_bits, sizeof(double)), 0);
      EXPECT_EQ(sa.evaluations, sb.evaluations);
      ASSERT_EQ(sa.saturation.has_value(), sb.saturation.has_value());
      if (sa.saturation) {
        EXPECT_EQ(sa.saturation->p_value, sb.saturation->p_value);
        EXPECT_EQ(sa.saturation->share_near_ceiling, sb.saturation->share_near_ceiling);
      }
    }
  }
  EXPECT_TRUE(used_ga);
  omp_set_num_threads(omp_get_num_procs());
}

TEST(Place, HistogramDiagnosisFlagsSetsTiedAtTheCeilingOnTheC54Problem) {
  // Smooth histories: samples follow a trajectory, so at m >= 3 many combinations reach
  // H(Y binned) exactly and the patent's argmax is a pick among ties.
  const auto input = synthetic::c54_input(0.01, 3);
  auto options = quick_options();
  options.methods = {Method::kHistogramMi};
  options.saturation.sampled_combinations = 200;
  const auto r = place_all(input, options);
  int tied = 0;
  for (const auto& t : r.targets)
    for (const auto& s : t.selections) {
      ASSERT_TRUE(s.saturation.has_value());
      const auto& d = *s.saturation;
      EXPECT_NEAR(d.score_bits, s.score, 1e-12);
      EXPECT_LE(d.score_bits, d.ceiling_bits + 1e-12);
      const bool rule = d.share_near_ceiling >= options.saturation.share_threshold ||
                        d.p_value > options.saturation.alpha ||
                        (d.at_ceiling && d.share_near_ceiling > 0.0);
      EXPECT_EQ(d.saturated, rule) << t.target << " m = " << s.m;
      EXPECT_EQ(d.saturated, !d.reason.empty());
      if (s.m == 1) {
        EXPECT_FALSE(d.saturated) << t.target << ": " << d.reason;
      }
      tied += d.at_ceiling && d.share_near_ceiling > 0.0;
    }
  EXPECT_GE(tied, 1) << "dz reaches the ceiling with ties from m = 3 on";
}

TEST(Place, KsgSeesADocumentedSubsampleOfLargePools) {
  const auto input = synthetic::c54_input(0.05, 6);
  auto options = quick_options();
  options.mirror_twins = false;
  options.ksg_max_candidates = 20;
  options.m_max = 3;
  options.methods = {Method::kKsgGreedy, Method::kCorrelation};
  const auto r = place_all(input, options);
  // The best-correlated candidate (the correlation ranking's first pick) is in the subsample, and
  // every KSG choice comes from it.
  for (const auto& t : r.targets) {
    ASSERT_EQ(t.ksg_pool.size(), 20u);
    EXPECT_TRUE(std::is_sorted(t.ksg_pool.begin(), t.ksg_pool.end()));
    for (const auto& s : t.selections) {
      if (s.method == Method::kCorrelation && s.m == 1) {
        EXPECT_TRUE(std::binary_search(t.ksg_pool.begin(), t.ksg_pool.end(), s.columns[0]));
      }
      if (s.method == Method::kKsgGreedy) {
        for (int c : s.columns) {
          EXPECT_TRUE(std::binary_search(t.ksg_pool.begin(), t.ksg_pool.end(), c));
        }
      }
    }
  }
}

TEST(Place, RejectsInconsistentInputWithTypedErrors) {
  auto input = synthetic::c54_input(0.0, 4);
  auto bad = input;
  bad.ids[3] = bad.ids[2];
  EXPECT_THROW(place_all(bad, quick_options()), tt::core::DataError);
  bad = input;
  bad.targets[0].values_m.conservativeResize(5);
  EXPECT_THROW(place_all(bad, quick_options()), tt::core::DataError);
  bad = input;
  bad.temperatures_K(4, 4) = NAN;
  EXPECT_THROW(place_all(bad, quick_options()), tt::core::DataError);
  auto options = quick_options();
  options.temperature_bins = 1;
  EXPECT_THROW(place_all(input, options), tt::core::DataError);
}
