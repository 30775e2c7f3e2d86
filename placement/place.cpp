#include "placement/place.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <string>

#include "core/errors.hpp"
#include "core/rng.hpp"
#include "core/timing.hpp"
#include "placement/baselines.hpp"
#include "placement/estimation.hpp"
#include "placement/gaussian.hpp"
#include "placement/histogram_mi.hpp"
#include "placement/ksg.hpp"
#include "placement/qr_pod.hpp"
#include "placement/series.hpp"
#include "placement/twins.hpp"

namespace tt::placement {

using core::seconds_since;

namespace {

using Clock = std::chrono::steady_clock;

bool wants(const PlacementOptions& o, Method m) {
  return std::find(o.methods.begin(), o.methods.end(), m) != o.methods.end();
}

void validate(const PlacementInput& in, const PlacementOptions& o) {
  const auto n = static_cast<Eigen::Index>(in.ids.size());
  if (n == 0) throw core::DataError("placement: no candidates: expected at least one history");
  if (in.temperatures_K.cols() != n || in.positions_m.rows() != n)
    throw core::DataError("placement: " + std::to_string(n) + " ids, " +
                          std::to_string(in.positions_m.rows()) + " positions and " +
                          std::to_string(in.temperatures_K.cols()) +
                          " temperature columns: expected one of each per candidate");
  if (in.temperatures_K.rows() != in.times_s.size())
    throw core::DataError("placement: " + std::to_string(in.temperatures_K.rows()) +
                          " temperature rows for " + std::to_string(in.times_s.size()) +
                          " times: expected one row per time");
  if (!in.temperatures_K.allFinite() || !in.times_s.allFinite())
    throw core::DataError("placement: the temperature histories or times hold NaN or infinity");
  std::set<std::int32_t> seen;
  for (auto id : in.ids)
    if (!seen.insert(core::index_of(id)).second)
      throw core::DataError("placement: candidate id " + std::to_string(core::index_of(id)) +
                            " appears twice: ids must be distinct");
  if (in.targets.empty()) throw core::DataError("placement: no error target (expected dy, dz)");
  for (const auto& t : in.targets)
    if (t.values_m.size() != in.times_s.size() || !t.values_m.allFinite())
      throw core::DataError("placement: target '" + t.name + "' has " +
                            std::to_string(t.values_m.size()) + " values for " +
                            std::to_string(in.times_s.size()) +
                            " times (or non-finite values): expected one finite value per time");
  if (in.estimation)
    placement::validate(*in.estimation, n, static_cast<Eigen::Index>(in.targets.size()));
  if (o.samples != 0 && o.samples < 3)
    throw core::DataError("placement.samples = " + std::to_string(o.samples) +
                          ": must be 0 (as given) or >= 3 (the patent uses 100)");
  if (o.m_max < 1)
    throw core::DataError("placement.m_max = " + std::to_string(o.m_max) + ": must be >= 1");
  if (!(o.collinearity.max_correlation > 0.0 && o.collinearity.max_correlation < 1.0))
    throw core::DataError(
        "placement.max_correlation = " + std::to_string(o.collinearity.max_correlation) +
        ": must be in (0, 1), e.g. 0.999");
  if (!(o.collinearity.min_residual > 0.0 && o.collinearity.min_residual < 1.0))
    throw core::DataError(
        "placement.min_residual = " + std::to_string(o.collinearity.min_residual) +
        ": must be in (0, 1), e.g. 1e-8");
}

/// The set of pool positions `positions` as candidate columns.
std::vector<int> columns_of(std::span<const int> pool, std::span<const int> positions) {
  std::vector<int> c;
  for (int p : positions) c.push_back(pool[static_cast<std::size_t>(p)]);
  return c;
}

/// Everything one target's methods share.
struct TargetData {
  const LinearProblem& linear;
  const BinnedProblem& binned;
  const std::vector<int>& pool;
  const PlacementInput& input;
  const PlacementOptions& options;
  std::size_t target_index;
  const GreedyPath& greedy;  ///< Gaussian forward selection: the GA's fallback start
};

Selection selection(const TargetData& d, Method method, std::string search,
                    std::vector<int> columns, double score, std::string kind, double seconds) {
  Selection s;
  s.method = method;
  s.search = std::move(search);
  s.m = static_cast<int>(columns.size());
  for (int c : columns) s.ids.push_back(d.input.ids[static_cast<std::size_t>(c)]);
  const auto r2 = set_r_squared(d.linear, columns, d.options.collinearity);
  s.gaussian_bits = r2 ? gaussian_mi_bits(*r2) : std::numeric_limits<double>::quiet_NaN();
  s.columns = std::move(columns);
  s.score = score;
  s.score_kind = std::move(kind);
  s.seconds = seconds;
  return s;
}

std::uint64_t stream(const TargetData& d, Method method, int m) {
  return (d.target_index * 64 + static_cast<std::size_t>(method)) * 64 +
         static_cast<std::size_t>(m);
}

/// Exhaustive where C(pool, m) allows, the genetic search beyond.
SearchResult searched(const TargetData& d, Method method, int m, const SetFitness& fitness,
                      std::string& search) {
  const int p = static_cast<int>(d.pool.size());
  if (combination_count(p, m) <= d.options.exhaustive_limit) {
    search = "exhaustive";
    return exhaustive_search(p, m, fitness);
  }
  search = "ga";
  GaOptions ga = d.options.ga;
  ga.seed = core::derived_seed(d.options.seed, stream(d, method, 0));
  // The greedy set of m as pool positions (the pool is ascending).
  std::vector<std::vector<int>> fallback;
  if (static_cast<int>(d.greedy.order.size()) >= m) {
    std::vector<int> positions;
    for (int k = 0; k < m; ++k) {
      const int column = d.greedy.order[static_cast<std::size_t>(k)];
      positions.push_back(static_cast<int>(std::lower_bound(d.pool.begin(), d.pool.end(), column) -
                                           d.pool.begin()));
    }
    fallback.push_back(std::move(positions));
  }
  return genetic_search(p, m, fitness, ga, fallback);
}

void histogram_selections(const TargetData& d, const Eigen::VectorXd& mi_bits,
                          std::vector<Selection>& out) {
  const auto& o = d.options;
  const int m_max = std::min({o.m_max, 7, static_cast<int>(d.pool.size())});
  for (int m = 1; m <= m_max; ++m) {
    const auto start = Clock::now();
    Selection s;
    if (m == 1) {
      const auto top = top_ranked(mi_bits, d.pool, 1, d.linear, o.collinearity);
      if (top.empty()) continue;
      s = selection(d, Method::kHistogramMi, "ranking", top, mi_bits(top[0]), "histogram_bits",
                    0.0);
      s.evaluations = static_cast<std::int64_t>(d.pool.size());
    } else {
      const SetFitness fitness = [&](std::span<const int> positions) {
        const auto cols = columns_of(d.pool, positions);
        if (!set_r_squared(d.linear, cols, o.collinearity))
          return -std::numeric_limits<double>::infinity();
        return joint_mi_bits(d.binned, cols);
      };
      std::string search;
      const auto r = searched(d, Method::kHistogramMi, m, fitness, search);
      if (!std::isfinite(r.fitness)) continue;  // every combination inadmissible
      s = selection(d, Method::kHistogramMi, search, columns_of(d.pool, r.best), r.fitness,
                    "histogram_bits", 0.0);
      s.evaluations = r.evaluations;
    }
    s.saturation =
        saturation_diagnosis(d.binned, s.columns, d.pool, o.saturation,
                             core::derived_seed(o.seed, stream(d, Method::kHistogramMi, m)));
    s.seconds = seconds_since(start);
    out.push_back(std::move(s));
  }
}

void path_selections(const TargetData& d, Method method, const GreedyPath& path,
                     const std::string& kind, std::vector<Selection>& out) {
  for (std::size_t m = 1; m <= path.order.size(); ++m)
    out.push_back(selection(
        d, method, "greedy",
        std::vector<int>(path.order.begin(), path.order.begin() + static_cast<std::ptrdiff_t>(m)),
        path.scores[m - 1], kind, path.seconds[m - 1]));
}

void gaussian_ga_selections(const TargetData& d, std::vector<Selection>& out) {
  const auto& o = d.options;
  const SetFitness fitness = [&](std::span<const int> positions) {
    const auto r2 = set_r_squared(d.linear, columns_of(d.pool, positions), o.collinearity);
    return r2 ? gaussian_mi_bits(*r2) : -std::numeric_limits<double>::infinity();
  };
  for (int m = 1; m <= std::min(o.m_max, static_cast<int>(d.pool.size())); ++m) {
    const auto start = Clock::now();
    std::string search;
    const auto r = searched(d, Method::kGaussianGa, m, fitness, search);
    if (!std::isfinite(r.fitness)) continue;
    auto s = selection(d, Method::kGaussianGa, search, columns_of(d.pool, r.best), r.fitness,
                       "gaussian_bits", seconds_since(start));
    s.evaluations = r.evaluations;
    out.push_back(std::move(s));
  }
}

void ranked_selections(const TargetData& d, Method method, const Eigen::VectorXd& scores,
                       const std::string& kind, double setup_seconds, std::vector<Selection>& out) {
  for (int m = 1; m <= std::min(d.options.m_max, static_cast<int>(d.pool.size())); ++m) {
    const auto start = Clock::now();
    const auto top = top_ranked(scores, d.pool, m, d.linear, d.options.collinearity);
    if (static_cast<int>(top.size()) < m) break;
    out.push_back(selection(d, method, "ranking", top, scores(top.back()), kind,
                            setup_seconds + seconds_since(start)));
  }
}

/// KSG's subsample of a large pool, ascending columns: the limit/2 candidates with the largest
/// |r| with the target (where the answer most likely is), plus limit − limit/2 spread evenly over
/// the rest of the pool in column order (so that the top ones, often near-collinear, do not crowd
/// out every other direction).
std::vector<int> ksg_pool_of(const std::vector<int>& pool, const LinearProblem& linear, int limit) {
  if (static_cast<int>(pool.size()) <= limit) return pool;
  std::vector<int> order = pool;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    const double ra = std::abs(linear.r_y(a)), rb = std::abs(linear.r_y(b));
    if (ra != rb) return ra > rb;
    return a < b;
  });
  const auto top = static_cast<std::size_t>(limit / 2);
  std::vector<int> chosen(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(top));
  std::vector<int> rest(order.begin() + static_cast<std::ptrdiff_t>(top), order.end());
  std::sort(rest.begin(), rest.end());
  const std::size_t spread = static_cast<std::size_t>(limit) - top;
  for (std::size_t k = 0; k < spread; ++k) chosen.push_back(rest[k * rest.size() / spread]);
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

}  // namespace

std::string_view method_name(Method method) {
  return core::name_in(kMethodNames, method);
}

std::vector<Method> all_methods() {
  std::vector<Method> methods;
  for (const auto& entry : kMethodNames) methods.push_back(entry.value);
  return methods;
}

namespace {

void estimation_selections(const TargetData& d, std::vector<Selection>& out) {
  const int target = static_cast<int>(d.target_index);
  // The other methods' guard: a candidate that is not a sensor of its own on the histories.
  const Admissible admissible = [&](std::span<const int> chosen, int candidate) {
    return adds_direction(d.linear, chosen, candidate, d.options.collinearity);
  };
  const GreedyPath path = estimation_greedy(*d.input.estimation, d.pool, d.options.m_max,
                                            std::span<const int>(&target, 1), admissible);
  for (std::size_t m = 1; m <= path.order.size(); ++m) {
    // The score is the RMS posterior sigma over the readings [m]: lower is better.
    out.push_back(selection(
        d, Method::kObserverVariance, "greedy",
        std::vector<int>(path.order.begin(), path.order.begin() + static_cast<std::ptrdiff_t>(m)),
        std::sqrt(path.scores[m - 1]), "posterior_sigma_m", path.seconds[m - 1]));
  }
}

void ksg_selections(const TargetData& d, TargetResult& tr) {
  const auto& o = d.options;
  tr.ksg_pool = ksg_pool_of(d.pool, d.linear, o.ksg_max_candidates);
  const auto ksg =
      ksg_problem(d.linear, o.ksg_k, core::derived_seed(o.seed, stream(d, Method::kKsgGreedy, 63)));
  const int m_max = std::min(o.m_max, static_cast<int>(tr.ksg_pool.size()));
  if (wants(o, Method::kKsgGreedy))
    path_selections(d, Method::kKsgGreedy,
                    ksg_greedy(ksg, d.linear, tr.ksg_pool, m_max, o.collinearity), "ksg_bits",
                    tr.selections);
  if (wants(o, Method::kJmiKsg))
    path_selections(d, Method::kJmiKsg,
                    jmi_greedy(ksg, d.linear, tr.ksg_pool, m_max, o.collinearity), "ksg_bits",
                    tr.selections);
}

void qr_pod_selections(const TargetData& d, const Eigen::MatrixXd& modes, double pod_seconds,
                       std::vector<Selection>& out) {
  const auto& o = d.options;
  for (int m = 1; m <= std::min<int>(o.m_max, static_cast<int>(d.pool.size())); ++m) {
    const auto start = Clock::now();
    const Eigen::MatrixXd lead = modes.leftCols(std::min<Eigen::Index>(m, modes.cols()));
    const auto cols = qr_pivots(lead, d.pool, m, d.linear, o.collinearity);
    if (static_cast<int>(cols.size()) < m) break;  // the modes are exhausted
    auto s = selection(d, Method::kQrPod, "qr", cols, 0.0, "gaussian_bits",
                       pod_seconds + seconds_since(start));
    s.score = s.gaussian_bits;
    out.push_back(std::move(s));
  }
}

/// Every method in options.methods for target t on the resampled histories.
TargetResult target_result(const PlacementInput& input, const PlacementOptions& o,
                           const PlacementResult& result, const Eigen::MatrixXd& temperatures,
                           const Eigen::MatrixXd& modes, std::size_t t) {
  const auto& target = input.targets[t];
  const Eigen::VectorXd y =
      o.samples > 0
          ? Eigen::VectorXd(resampled(input.times_s, target.values_m, result.sample_times_s))
          : target.values_m;
  const auto linear = linear_problem(temperatures, y);
  const auto binned = binned_problem(temperatures, y, o.temperature_bins, o.error_bins);
  const bool searches = wants(o, Method::kGaussianGreedy) || wants(o, Method::kGaussianGa) ||
                        wants(o, Method::kHistogramMi);
  const GreedyPath greedy =
      searches ? gaussian_greedy(linear, result.pool, o.m_max, o.collinearity) : GreedyPath{};
  const TargetData d{linear, binned, result.pool, input, o, t, greedy};

  TargetResult tr;
  tr.target = target.name;
  tr.mi_bits = single_mi_bits(binned);
  tr.mi_rank = ranks_descending(tr.mi_bits);
  auto& out = tr.selections;
  auto start = Clock::now();
  // A method that took progress_after_s or more says so as it is done, with its wall time.
  const auto done = [&](std::string_view methods) {
    if (o.progress && seconds_since(start) >= o.progress_after_s) {
      char took[32];
      std::snprintf(took, sizeof took, "%.1f s", seconds_since(start));
      o.progress(target.name + ": " + std::string(methods) + ", m = 1.." + std::to_string(o.m_max) +
                 ", " + took);
    }
    start = Clock::now();
  };
  if (wants(o, Method::kHistogramMi)) {
    histogram_selections(d, tr.mi_bits, out);
    done(method_name(Method::kHistogramMi));
  }
  if (wants(o, Method::kGaussianGreedy)) {
    path_selections(d, Method::kGaussianGreedy, greedy, "gaussian_bits", out);
    done(method_name(Method::kGaussianGreedy));
  }
  if (wants(o, Method::kGaussianGa)) {
    gaussian_ga_selections(d, out);
    done(method_name(Method::kGaussianGa));
  }
  if (wants(o, Method::kKsgGreedy) || wants(o, Method::kJmiKsg)) {
    ksg_selections(d, tr);
    done("KSG and JMI");
  }
  if (wants(o, Method::kQrPod)) {
    qr_pod_selections(d, modes, result.pod_seconds, out);
    done(method_name(Method::kQrPod));
  }
  if (wants(o, Method::kCorrelation)) {
    ranked_selections(d, Method::kCorrelation, linear.r_y.cwiseAbs(), "abs_r", 0.0, out);
    done(method_name(Method::kCorrelation));
  }
  if (wants(o, Method::kGreyRelational)) {
    const auto grades = grey_relational_grades(temperatures, y, o.grey_rho);
    ranked_selections(d, Method::kGreyRelational, grades, "grey_grade", seconds_since(start), out);
    done(method_name(Method::kGreyRelational));
  }
  if (wants(o, Method::kObserverVariance) && input.estimation) {
    estimation_selections(d, out);
    done(method_name(Method::kObserverVariance));
  }
  return tr;
}

}  // namespace

PlacementResult place_all(const PlacementInput& input, const PlacementOptions& options) {
  validate(input, options);
  const auto& o = options;

  // 1. A common sample grid.
  PlacementResult result;
  result.ids = input.ids;
  result.positions_m = input.positions_m;
  result.options = o;
  Eigen::MatrixXd temperatures = input.temperatures_K;
  if (o.samples > 0) {
    result.sample_times_s = sample_times(input.times_s, o.samples);
    temperatures = resampled(input.times_s, input.temperatures_K, result.sample_times_s);
  } else {
    result.sample_times_s = input.times_s;
  }

  // 2. Twins and the pools the searches draw from.
  const int n = static_cast<int>(input.ids.size());
  if (o.mirror_twins)
    result.twins = mirror_twins(input.positions_m, o.mirror_plane_x_m, o.mirror_tolerance_m);
  result.pool = search_pool(n, result.twins);

  // 3. POD modes do not depend on the target: once.
  Eigen::MatrixXd modes;
  if (wants(o, Method::kQrPod)) {
    const auto start = Clock::now();
    modes = pod_modes(temperatures, o.m_max);
    result.pod_seconds = seconds_since(start);
  }

  // 4. Every method for every target.
  for (std::size_t t = 0; t < input.targets.size(); ++t)
    result.targets.push_back(target_result(input, o, result, temperatures, modes, t));
  return result;
}

}  // namespace tt::placement
