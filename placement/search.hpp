// Searches over m-sensor combinations of a pool: exhaustive where the count allows, and the
// patent's genetic algorithm beyond. Combinations are sorted position lists into the pool.
// Fitness evaluations run in parallel (core/parallel.hpp); every random draw happens serially
// from one seeded generator, so the result does not depend on the thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace tt::placement {

/// Fitness of a sorted combination of pool positions; -infinity marks an inadmissible one
/// (e.g. two collinear twins). Must be thread-safe and deterministic.
using SetFitness = std::function<double(std::span<const int>)>;

struct GaOptions {
  // Defaults tuned on 54 candidates, m = 3: the optimum in 198 of 200 seeds with at most
  // 24 + 50·22 = 1124 evaluations (4.5 % of C(54, 3)).
  int population = 24;
  int max_generations = 50;
  int stall_generations = 25;  ///< stop after this many generations without improvement
  double crossover_rate = 0.9;
  double mutation_rate = 0.3;  ///< per child: probability that one gene is replaced
  int tournament = 3;
  int elites = 2;
  std::uint64_t seed = 1;
  /// A generation's new combinations are evaluated in parallel only from this many on: on a
  /// shared 2-core machine one parallel region per generation of ~22 cheap Gaussian evaluations
  /// cost 100 times what it saved (6.4 s against 0.06 s for m = 1..6 on 4000 candidates).
  /// The order of evaluation, and so the result, is the same either way.
  int min_parallel_batch = 64;
};

struct SearchResult {
  std::vector<int> best;  ///< sorted pool positions
  double fitness = 0.0;
  std::int64_t evaluations = 0;  ///< distinct combinations evaluated
  int generations = 0;           ///< 0 for the exhaustive search
};

/// C(n, m), saturating at INT64_MAX.
std::int64_t combination_count(int n, int m);

/// Every combination of m out of pool_size; ties go to the lexicographically first combination.
SearchResult exhaustive_search(int pool_size, int m, const SetFitness& fitness);

/// The seeded genetic algorithm: random initial combinations, tournament selection, crossover
/// that keeps the parents' shared genes and fills from the rest of their union, mutation that
/// swaps one gene for a random outsider, elitism; every distinct combination evaluated once.
/// `fallback`: admissible combinations (e.g. a greedy path's) that take the places of the first
/// initial members when none of the random ones is admissible. Among thousands of smooth
/// surface histories nearly every random m-set can hold a collinear pair, and a population
/// with no finite fitness never moves; when one random member is admissible they are not used,
/// so they cannot change a result the random start reaches on its own.
SearchResult genetic_search(int pool_size, int m, const SetFitness& fitness,
                            const GaOptions& options,
                            const std::vector<std::vector<int>>& fallback = {});

}  // namespace tt::placement
