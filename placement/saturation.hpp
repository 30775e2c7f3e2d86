// Where the patent's method breaks. Once almost every sample sits alone in its joint cell, the
// histogram estimate of I(Y; T_S) collapses to about H(Y binned), whichever sensors are chosen,
// and noise scores like signal. Two symptoms are measured for a chosen set:
// - the share of m-sensor combinations whose score lies within a margin of that ceiling (when the
//   chosen set is at the ceiling too, the choice among the tied sets is arbitrary);
// - a shuffle test: Y permuted relative to the sensors, the chosen set re-scored each time; a
//   real dependence scores above (almost) every shuffle, a saturated estimate does not.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "placement/histogram_mi.hpp"

namespace tt::placement {

struct SaturationOptions {
  double margin_bits = 0.1;        ///< "near the ceiling" means within this of H(Y binned)
  double share_threshold = 0.5;    ///< saturated when at least this share is near the ceiling
  int shuffles = 200;              ///< permutations of Y in the shuffle test
  double alpha = 0.01;             ///< saturated when the shuffle p-value exceeds this
  int sampled_combinations = 200;  ///< random m-sensor combinations scored for the share (m >= 2)
};

struct SaturationDiagnosis {
  int m = 0;
  double ceiling_bits = 0.0;  ///< H(Y binned), the largest value any estimate can take
  double score_bits = 0.0;    ///< histogram I(Y; T_S) of the chosen set
  double margin_bits = 0.0;
  int combinations_scored = 0;      ///< all pool candidates for m = 1, a random sample otherwise
  double share_near_ceiling = 0.0;  ///< share of those within margin_bits of the ceiling
  bool at_ceiling = false;          ///< the chosen set itself scores within margin_bits of it
  double singleton_share = 0.0;     ///< share of samples alone in their joint temperature cell
  int shuffles = 0;
  double shuffle_mean_bits = 0.0;
  double shuffle_sd_bits = 0.0;
  double shuffle_max_bits = 0.0;
  double excess_bits = 0.0;  ///< score minus the shuffled mean: the bias-corrected score
  double p_value = 1.0;      ///< (1 + #{shuffled >= score}) / (1 + shuffles)
  bool saturated = false;
  std::string reason;  ///< why it is saturated; empty otherwise
};

/// Diagnosis of the histogram estimate for the candidate columns `chosen` (m of them), against
/// combinations drawn from `pool` (candidate columns). Saturated when any of:
/// share_near_ceiling >= share_threshold; p_value > alpha; at_ceiling with share_near_ceiling > 0.
/// Seeded; serial, so thread-independent.
SaturationDiagnosis saturation_diagnosis(const BinnedProblem& problem, std::span<const int> chosen,
                                         std::span<const int> pool,
                                         const SaturationOptions& options, std::uint64_t seed);

}  // namespace tt::placement
