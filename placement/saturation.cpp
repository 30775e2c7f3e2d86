#include "placement/saturation.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.hpp"
#include "core/rng.hpp"
#include "placement/random.hpp"

namespace tt::placement {

namespace {

void require_saturation(int m, std::size_t pool_size, const SaturationOptions& options) {
  if (m < 1 || static_cast<int>(pool_size) < m)
    throw core::DataError("placement: saturation diagnosis of " + std::to_string(m) +
                          " sensors from a pool of " + std::to_string(pool_size) +
                          ": expected 1 <= m <= pool size");
  if (options.sampled_combinations < 1)
    throw core::DataError("placement.saturation.sampled_combinations = " +
                          std::to_string(options.sampled_combinations) + ": must be >= 1");
  if (!(options.alpha > 0.0) || 1.0 / (1.0 + options.shuffles) > options.alpha)
    throw core::DataError("placement.saturation: shuffles = " + std::to_string(options.shuffles) +
                          " with alpha = " + std::to_string(options.alpha) +
                          ": the smallest p-value 1/(1 + shuffles) must not exceed alpha; hint: "
                          "use at least 1/alpha − 1 shuffles (99 for alpha = 0.01)");
}

/// How crowded the top is: d.combinations_scored and d.share_near_ceiling from every single
/// sensor of the pool (m = 1) or sampled combinations of m (drawn from `seed`'s stream 0).
void score_crowding(SaturationDiagnosis& d, const BinnedProblem& problem, std::span<const int> pool,
                    const SaturationOptions& options, std::uint64_t seed) {
  const int m = d.m;
  std::mt19937_64 gen = core::generator(seed, 0);
  int near = 0;
  if (m == 1) {
    for (int c : pool) {
      const int set[1] = {c};
      near += joint_mi_bits(problem, set) >= d.ceiling_bits - options.margin_bits;
    }
    d.combinations_scored = static_cast<int>(pool.size());
  } else {
    std::vector<int> set;
    for (int k = 0; k < options.sampled_combinations; ++k) {
      set.clear();
      while (static_cast<int>(set.size()) < m) {
        const int c = pool[static_cast<std::size_t>(
            uniform_index(gen, static_cast<std::int64_t>(pool.size())))];
        if (std::find(set.begin(), set.end(), c) == set.end()) set.push_back(c);
      }
      near += joint_mi_bits(problem, set) >= d.ceiling_bits - options.margin_bits;
    }
    d.combinations_scored = options.sampled_combinations;
  }
  d.share_near_ceiling = static_cast<double>(near) / d.combinations_scored;
}

/// The shuffle test: the chosen set's score against Y shuffled `options.shuffles` times
/// (permutations from `seed`'s stream 1), into d's shuffle figures and p-value.
void shuffle_test(SaturationDiagnosis& d, const BinnedProblem& problem, std::span<const int> chosen,
                  const SaturationOptions& options, std::uint64_t seed) {
  std::mt19937_64 shuffle_gen = core::generator(seed, 1);
  std::vector<std::uint8_t> y(problem.y_bins.size());
  double sum = 0.0, sum2 = 0.0;
  int above = 0;
  d.shuffle_max_bits = -INFINITY;
  for (int k = 0; k < options.shuffles; ++k) {
    const auto perm = random_permutation(shuffle_gen, problem.samples);
    for (std::size_t s = 0; s < y.size(); ++s)
      y[s] = problem.y_bins[static_cast<std::size_t>(perm[s])];
    const double bits = joint_mi_bits(problem, chosen, y);
    sum += bits;
    sum2 += bits * bits;
    d.shuffle_max_bits = std::max(d.shuffle_max_bits, bits);
    // A shuffle that equals the real score to round-off counts against it: at the ceiling both
    // are H(Y) and nothing has been shown.
    above += bits >= d.score_bits - 1e-9;
  }
  d.shuffles = options.shuffles;
  d.shuffle_mean_bits = sum / options.shuffles;
  d.shuffle_sd_bits =
      std::sqrt(std::max(0.0, sum2 / options.shuffles - d.shuffle_mean_bits * d.shuffle_mean_bits));
  d.excess_bits = d.score_bits - d.shuffle_mean_bits;
  d.p_value = (1.0 + above) / (1.0 + options.shuffles);
}

/// Why the diagnosis is saturated; empty when it is not.
std::string saturation_reason(const SaturationDiagnosis& d, const SaturationOptions& options) {
  std::ostringstream why;
  if (d.share_near_ceiling >= options.share_threshold)
    why << d.share_near_ceiling * 100.0 << " % of the " << d.combinations_scored
        << " combinations scored lie within " << options.margin_bits
        << " bit of the ceiling H(Y) = " << d.ceiling_bits << " bit";
  if (d.at_ceiling && d.share_near_ceiling > 0.0 &&
      d.share_near_ceiling < options.share_threshold) {
    why << "the chosen set scores at the ceiling H(Y) = " << d.ceiling_bits << " bit and so do "
        << d.share_near_ceiling * 100.0 << " % of the " << d.combinations_scored
        << " combinations scored: the choice among them is arbitrary";
  }
  if (d.p_value > options.alpha) {
    if (!why.str().empty()) why << "; ";
    why << "shuffle p = " << d.p_value << " > " << options.alpha
        << ": the chosen set does not score above Y shuffled against it";
  }
  return why.str();
}

}  // namespace

SaturationDiagnosis saturation_diagnosis(const BinnedProblem& problem, std::span<const int> chosen,
                                         std::span<const int> pool,
                                         const SaturationOptions& options, std::uint64_t seed) {
  const int m = static_cast<int>(chosen.size());
  require_saturation(m, pool.size(), options);
  SaturationDiagnosis d;
  d.m = m;
  d.margin_bits = options.margin_bits;
  d.ceiling_bits = binned_entropy_bits(problem.y_bins, problem.error_bins);
  d.score_bits = joint_mi_bits(problem, chosen);
  d.singleton_share = singleton_share(problem, chosen);

  // 1. How crowded the top is: scores of many combinations against the ceiling.
  score_crowding(d, problem, pool, options, seed);
  d.at_ceiling = d.score_bits >= d.ceiling_bits - options.margin_bits;

  // 2. The shuffle test.
  shuffle_test(d, problem, chosen, options, seed);

  // 3. The verdict.
  d.reason = saturation_reason(d, options);
  d.saturated = !d.reason.empty();
  return d;
}

}  // namespace tt::placement
