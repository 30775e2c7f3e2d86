#include "placement/search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "core/rng.hpp"
#include "placement/random.hpp"

namespace tt::placement {

namespace {

void require_search(int pool_size, int m) {
  if (m < 1 || m > pool_size)
    throw core::DataError("placement: search for " + std::to_string(m) + " sensors among " +
                          std::to_string(pool_size) +
                          " candidates: expected 1 <= m <= #candidates");
}

/// Strictly better, with ties resolved towards the lexicographically smaller combination.
bool better(double fa, const std::vector<int>& a, double fb, const std::vector<int>& b) {
  if (fa != fb) return fa > fb;
  return a < b;
}

std::vector<int> random_combination(std::mt19937_64& gen, int pool_size, int m) {
  std::vector<int> c;
  c.reserve(static_cast<std::size_t>(m));
  while (static_cast<int>(c.size()) < m) {
    const int g = static_cast<int>(uniform_index(gen, pool_size));
    if (std::find(c.begin(), c.end(), g) == c.end()) c.push_back(g);
  }
  std::sort(c.begin(), c.end());
  return c;
}

}  // namespace

std::int64_t combination_count(int n, int m) {
  if (m < 0 || m > n) return 0;
  m = std::min(m, n - m);
  // C(n, i) = C(n, i-1) · (n - i + 1) / i stays an integer at every step.
  unsigned __int128 c = 1;
  for (int i = 1; i <= m; ++i) {
    c = c * static_cast<unsigned>(n - i + 1) / static_cast<unsigned>(i);
    if (c > static_cast<unsigned __int128>(std::numeric_limits<std::int64_t>::max()))
      return std::numeric_limits<std::int64_t>::max();
  }
  return static_cast<std::int64_t>(c);
}

SearchResult exhaustive_search(int pool_size, int m, const SetFitness& fitness) {
  require_search(pool_size, m);
  const std::int64_t count = combination_count(pool_size, m);
  if (count > 50'000'000)
    throw core::DataError("placement: exhaustive search over " + std::to_string(count) +
                          " combinations: too many; hint: use the genetic search");
  std::vector<int> all;
  all.reserve(static_cast<std::size_t>(count * m));
  std::vector<int> c(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) c[static_cast<std::size_t>(i)] = i;
  while (true) {
    all.insert(all.end(), c.begin(), c.end());
    int i = m - 1;
    while (i >= 0 && c[static_cast<std::size_t>(i)] == pool_size - m + i) --i;
    if (i < 0) break;
    ++c[static_cast<std::size_t>(i)];
    for (int j = i + 1; j < m; ++j)
      c[static_cast<std::size_t>(j)] = c[static_cast<std::size_t>(j - 1)] + 1;
  }
  std::vector<double> f(static_cast<std::size_t>(count));
  core::parallel_for(count, [&](std::ptrdiff_t k) {
    f[static_cast<std::size_t>(k)] =
        fitness(std::span<const int>(all.data() + k * m, static_cast<std::size_t>(m)));
  });
  // Combinations are in lexicographic order, so the first maximum is the tie winner.
  std::int64_t best = 0;
  for (std::int64_t k = 1; k < count; ++k)
    if (f[static_cast<std::size_t>(k)] > f[static_cast<std::size_t>(best)]) best = k;
  SearchResult r;
  r.best.assign(all.begin() + best * m, all.begin() + (best + 1) * m);
  r.fitness = f[static_cast<std::size_t>(best)];
  r.evaluations = count;
  return r;
}

namespace {

using Combination = std::vector<int>;
/// Every distinct combination evaluated, once, with its fitness.
using Evaluated = std::map<Combination, double>;

void require_ga(const GaOptions& options) {
  if (options.population < 2 || options.elites < 0 || options.elites >= options.population ||
      options.tournament < 1)
    throw core::DataError("placement.ga: population " + std::to_string(options.population) +
                          ", elites " + std::to_string(options.elites) + ", tournament " +
                          std::to_string(options.tournament) +
                          ": expected population >= 2, 0 <= elites < population, tournament >= 1");
}

/// Evaluates the not yet seen members of `batch` in parallel (from min_parallel_batch of them),
/// in first-appearance order, into `seen`.
void evaluate(Evaluated& seen, const std::vector<Combination>& batch, const SetFitness& fitness,
              int min_parallel_batch) {
  std::vector<const Combination*> fresh;
  std::map<Combination, bool> queued;
  for (const auto& c : batch)
    if (!seen.count(c) && queued.emplace(c, true).second) fresh.push_back(&c);
  std::vector<double> f(fresh.size());
  const auto one = [&](std::ptrdiff_t k) {
    f[static_cast<std::size_t>(k)] = fitness(*fresh[static_cast<std::size_t>(k)]);
  };
  const auto count = static_cast<std::ptrdiff_t>(fresh.size());
  if (count >= min_parallel_batch)
    core::parallel_for(count, one);
  else
    for (std::ptrdiff_t k = 0; k < count; ++k) one(k);
  for (std::size_t k = 0; k < fresh.size(); ++k) seen.emplace(*fresh[k], f[k]);
}

/// The initial population: distinct combinations while the pool allows.
std::vector<Combination> initial_population(std::mt19937_64& gen, int pool_size, int m,
                                            int population) {
  const std::int64_t distinct = combination_count(pool_size, m);
  std::vector<Combination> pop;
  for (int tries = 0; static_cast<int>(pop.size()) < population; ++tries) {
    auto c = random_combination(gen, pool_size, m);
    if (tries < 20 * population && static_cast<std::int64_t>(pop.size()) < distinct &&
        std::find(pop.begin(), pop.end(), c) != pop.end())
      continue;
    pop.push_back(std::move(c));
  }
  return pop;
}

/// Replaces the population's first members by the fallback combinations (sorted); throws
/// DataError for a fallback that is not m distinct positions of the pool.
void put_fallback(std::vector<Combination>& pop, const std::vector<Combination>& fallback,
                  int pool_size, int m) {
  for (std::size_t i = 0; i < fallback.size() && i < pop.size(); ++i) {
    auto c = fallback[i];
    std::sort(c.begin(), c.end());
    if (static_cast<int>(c.size()) != m || c.front() < 0 || c.back() >= pool_size ||
        std::adjacent_find(c.begin(), c.end()) != c.end())
      throw core::DataError("placement: GA fallback combination " + std::to_string(i) +
                            ": expected " + std::to_string(m) + " distinct positions in [0, " +
                            std::to_string(pool_size) + ")");
    pop[i] = std::move(c);
  }
}

/// Parent `a`, or with probability crossover_rate the genes shared by both parents and the
/// rest drawn from the union of both.
Combination crossed(std::mt19937_64& gen, const Combination& a, const Combination& b, int m,
                    double crossover_rate) {
  Combination child = a;
  if (uniform_unit(gen) < crossover_rate) {
    Combination shared, rest;
    std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(shared));
    std::set_symmetric_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(rest));
    child = shared;
    while (static_cast<int>(child.size()) < m) {
      const auto k =
          static_cast<std::size_t>(uniform_index(gen, static_cast<std::int64_t>(rest.size())));
      child.push_back(rest[k]);
      rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(k));
    }
  }
  return child;
}

/// The child with one gene moved to a position it lacks, with probability mutation_rate or
/// always when it is a clone of a member of `next`, so the search keeps moving instead of
/// re-evaluating clones; sorted.
Combination mutated(std::mt19937_64& gen, Combination child, const std::vector<Combination>& next,
                    int pool_size, int m, double mutation_rate) {
  const bool clone = std::find(next.begin(), next.end(), [&] {
                       auto s = child;
                       std::sort(s.begin(), s.end());
                       return s;
                     }()) != next.end();
  if ((clone || uniform_unit(gen) < mutation_rate) && m < pool_size) {
    const auto k = static_cast<std::size_t>(uniform_index(gen, m));
    int g = static_cast<int>(uniform_index(gen, pool_size));
    while (std::find(child.begin(), child.end(), g) != child.end())
      g = static_cast<int>(uniform_index(gen, pool_size));
    child[k] = g;
  }
  std::sort(child.begin(), child.end());
  return child;
}

}  // namespace

SearchResult genetic_search(int pool_size, int m, const SetFitness& fitness,
                            const GaOptions& options,
                            const std::vector<std::vector<int>>& fallback) {
  require_search(pool_size, m);
  require_ga(options);
  std::mt19937_64 gen = core::generator(options.seed, static_cast<std::uint64_t>(m));
  Evaluated seen;
  const auto evaluate_new = [&](const std::vector<Combination>& batch) {
    evaluate(seen, batch, fitness, options.min_parallel_batch);
  };

  std::vector<Combination> pop = initial_population(gen, pool_size, m, options.population);
  evaluate_new(pop);
  const bool none_admissible = std::all_of(
      pop.begin(), pop.end(), [&](const auto& c) { return !std::isfinite(seen.at(c)); });
  if (none_admissible && !fallback.empty()) {
    put_fallback(pop, fallback, pool_size, m);
    evaluate_new(pop);
  }

  auto fit = [&](const Combination& c) { return seen.at(c); };
  auto by_rank = [&](const Combination& a, const Combination& b) {
    return better(fit(a), a, fit(b), b);
  };
  std::sort(pop.begin(), pop.end(), by_rank);
  Combination best = pop.front();
  double best_f = fit(best);
  int stall = 0;
  int generation = 0;

  auto tournament = [&]() -> const Combination& {
    std::size_t w = static_cast<std::size_t>(uniform_index(gen, options.population));
    for (int t = 1; t < options.tournament; ++t) {
      const auto o = static_cast<std::size_t>(uniform_index(gen, options.population));
      if (by_rank(pop[o], pop[w])) w = o;
    }
    return pop[w];
  };

  while (generation < options.max_generations && stall < options.stall_generations) {
    ++generation;
    std::vector<Combination> next(pop.begin(), pop.begin() + options.elites);
    while (static_cast<int>(next.size()) < options.population) {
      const auto& a = tournament();
      const auto& b = tournament();
      Combination child = crossed(gen, a, b, m, options.crossover_rate);
      next.push_back(mutated(gen, std::move(child), next, pool_size, m, options.mutation_rate));
    }
    evaluate_new(next);
    pop = std::move(next);
    std::sort(pop.begin(), pop.end(), by_rank);
    if (better(fit(pop.front()), pop.front(), best_f, best)) {
      if (fit(pop.front()) > best_f)
        stall = 0;
      else
        ++stall;
      best = pop.front();
      best_f = fit(best);
    } else {
      ++stall;
    }
  }
  SearchResult r;
  r.best = best;
  r.fitness = best_f;
  r.evaluations = static_cast<std::int64_t>(seen.size());
  r.generations = generation;
  return r;
}

}  // namespace tt::placement
