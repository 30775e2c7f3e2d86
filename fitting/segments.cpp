#include "fitting/segments.hpp"

#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "fitting/features.hpp"

namespace tt::fitting {

std::vector<RowRange> speed_cycles(const Eigen::VectorXd& speed, Eigen::Index min_rows) {
  const Eigen::Index n = speed.size();
  std::vector<RowRange> ranges;
  if (n == 0) return ranges;
  std::vector<Eigen::Index> starts{0};
  bool started = false;  // the first start keeps the rest before it
  for (Eigen::Index i = 1; i < n; ++i) {
    if (speed(i - 1) == 0.0 && speed(i) > 0.0) {
      // The cycle starts at the last stopped sample, so that its re-zeroed drift is that of a
      // machine at rest and a drift that appears with the speed is seen whole.
      if (started) starts.push_back(i - 1);
      started = true;
    } else if (speed(i) > 0.0) {
      started = true;
    }
  }
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const Eigen::Index end = k + 1 < starts.size() ? starts[k + 1] : n;
    if (!ranges.empty() && end - starts[k] < min_rows)
      ranges.back().end = end;
    else
      ranges.push_back({starts[k], end});
  }
  // A short first cycle joins the next one.
  if (ranges.size() > 1 && ranges[0].end - ranges[0].begin < min_rows) {
    ranges[1].begin = 0;
    ranges.erase(ranges.begin());
  }
  return ranges;
}

double held_out_start(const Eigen::VectorXd& time, const Eigen::VectorXd& speed, double limit,
                      double fallback) {
  const Eigen::Index n = time.size();
  if (n == 0) throw core::DataError("held-out start of a run with no samples");
  const double t0 = time(0), span = time(n - 1) - time(0);
  double start = t0 + fallback * span;
  if (speed.size() == n)
    for (const RowRange& c : speed_cycles(speed))
      if (c.begin > 0 && time(c.begin) <= t0 + limit * span) start = time(c.begin);
  return start;
}

std::vector<RowRange> ranges_at(const Eigen::VectorXd& time, const std::vector<double>& cuts) {
  std::vector<RowRange> ranges;
  Eigen::Index begin = 0;
  const Eigen::Index n = time.size();
  for (std::size_t k = 0; k <= cuts.size(); ++k) {
    Eigen::Index end = begin;
    const double limit = k < cuts.size() ? cuts[k] : std::numeric_limits<double>::infinity();
    while (end < n && time(end) < limit) ++end;
    if (end > begin) ranges.push_back({begin, end});
    begin = end;
  }
  return ranges;
}

Segment segment_of(const std::string& name, const Eigen::VectorXd& time,
                   const Eigen::VectorXd& speed, const Eigen::MatrixXd& temperature,
                   const Eigen::MatrixXd& error, const std::vector<std::string>& sensor_names,
                   const std::vector<std::string>& target_names, RowRange range) {
  const Eigen::Index n = time.size();
  if (temperature.rows() != n || error.rows() != n || (speed.size() != 0 && speed.size() != n) ||
      range.begin < 0 || range.end > n || range.begin >= range.end)
    throw core::DataError("segment " + name + ": rows [" + std::to_string(range.begin) + ", " +
                          std::to_string(range.end) + ") of a run of " + std::to_string(n) +
                          " samples with " + std::to_string(temperature.rows()) +
                          " temperature and " + std::to_string(error.rows()) +
                          " error rows: expected matching sizes");
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = range.begin; i < range.end; ++i) {
    const bool complete = std::isfinite(time(i)) && temperature.row(i).allFinite() &&
                          error.row(i).allFinite() &&
                          (speed.size() == 0 || std::isfinite(speed(i)));
    if (complete) kept.push_back(i);
  }
  if (kept.size() < 2)
    throw core::DataError("segment " + name + ": " + std::to_string(kept.size()) +
                          " complete rows (no missing reading): expected at least 2");
  Segment s;
  s.rows = range;
  s.dropped_rows = static_cast<int>(range.end - range.begin) - static_cast<int>(kept.size());
  const auto m = static_cast<Eigen::Index>(kept.size());
  s.group.name = name;
  s.group.sensor_names = sensor_names;
  s.group.target_names = target_names;
  s.group.time.resize(m);
  s.group.temperature.resize(m, temperature.cols());
  s.group.error.resize(m, error.cols());
  s.speed = Eigen::VectorXd::Zero(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    const Eigen::Index i = kept[static_cast<std::size_t>(r)];
    s.group.time(r) = time(i);
    s.group.temperature.row(r) = temperature.row(i);
    s.group.error.row(r) = error.row(i) - error.row(kept.front());
    if (speed.size() != 0) s.speed(r) = speed(i);
  }
  if (speed.size() != 0) {
    s.group.inputs = s.speed;
    s.group.input_names = {"speed_rpm"};
  }
  return s;
}

std::vector<Group> segment_groups(const std::vector<Segment>& segments) {
  std::vector<Group> groups;
  for (const auto& s : segments) groups.push_back(s.group);
  return groups;
}

namespace {

/// Coefficients of a candidate, then the stronger ridge first: the order of simplicity.
std::pair<int, double> simplicity(const Candidate& c, int inputs) {
  return {coefficient_count(c.spec, static_cast<int>(c.sensor_set.sensors.size()), inputs),
          -c.spec.ridge_lambda};
}

}  // namespace

Blocks cross_validation_blocks(const std::vector<Segment>& pieces, int min_blocks,
                               Eigen::Index min_rows) {
  if (pieces.empty())
    throw core::DataError(
        "no training data: every run lies in the test window; hint: give more runs or a "
        "shorter test window");
  const int count = static_cast<int>(pieces.size());
  Blocks blocks;
  if (count >= min_blocks) {
    blocks.segments = pieces;
    blocks.origin = std::to_string(count) +
                    " training pieces as given (speed cycles where a run has a speed, whole runs "
                    "otherwise)";
    return blocks;
  }
  const int per_piece = (min_blocks + count - 1) / count;
  for (const auto& piece : pieces) {
    const Group& g = piece.group;
    const Eigen::Index n = g.time.size();
    if (n < per_piece * min_rows)
      throw core::DataError(
          "training piece '" + g.name + "' has " + std::to_string(n) + " samples: " +
          std::to_string(count) + " piece(s) give fewer than " + std::to_string(min_blocks) +
          " cross-validation blocks, and cutting it into " + std::to_string(per_piece) +
          " time blocks needs at least " + std::to_string(per_piece * min_rows) +
          " samples; hint: give longer runs, more runs, or a speed column whose stops cut the run "
          "into cycles");
    const double t0 = g.time(0), t1 = g.time(n - 1);
    std::vector<double> cuts;
    for (int k = 1; k < per_piece; ++k) cuts.push_back(t0 + (t1 - t0) * k / per_piece);
    int k = 0;
    for (const RowRange& r : ranges_at(g.time, cuts)) {
      // The speed is handed on only when the run had one (group.inputs), so that a run with no
      // speed column keeps none.
      const Eigen::VectorXd speed = g.inputs.cols() > 0 ? piece.speed : Eigen::VectorXd();
      blocks.segments.push_back(segment_of(g.name + ".b" + std::to_string(++k), g.time, speed,
                                           g.temperature, g.error, g.sensor_names, g.target_names,
                                           r));
    }
  }
  blocks.cut_in_time = true;
  blocks.origin = std::to_string(count) + " training piece(s) (fewer than " +
                  std::to_string(min_blocks) + ") each cut into " + std::to_string(per_piece) +
                  " time blocks of equal duration, re-zeroed at each block start: " +
                  std::to_string(blocks.segments.size()) + " blocks";
  return blocks;
}

namespace {

/// One candidate scored by leaving each block of the pool out in turn: fitted on the others and
/// its residual S on the block kept; the model is the fold without the first block. A fit that
/// throws leaves no model and says why.
CandidateResult scored_candidate(const std::vector<Group>& groups, const std::vector<int>& pool,
                                 int target, const Candidate& candidate, int index) {
  CandidateResult c;
  c.sensor_set = index;
  c.spec = index;
  std::vector<double> s;
  try {
    for (std::size_t k = 0; k < pool.size(); ++k) {
      std::vector<int> fit;
      for (std::size_t j = 0; j < pool.size(); ++j)
        if (j != k) fit.push_back(pool[j]);
      const FittedModel m = fitted_model(candidate.spec, group_subset(groups, fit),
                                         candidate.sensor_set.sensors, target);
      const Group& held = groups[static_cast<std::size_t>(pool[k])];
      s.push_back(residual_std(held.error.col(target) - predicted_error(m, held)));
      if (k == 0) c.model = m;
    }
    c.validation = accuracy(s);
  } catch (const std::exception& e) {
    c.model.reset();
    c.failure = e.what();
  }
  return c;
}

/// The index of the lowest held-out mean square S² (the quantity a test RMS measures; a mean of
/// S would let a candidate that fails badly on one block through when it is good on the others),
/// ties to the simpler candidate; -1 when every candidate failed.
int lowest_candidate(const std::vector<CandidateResult>& scored,
                     const std::vector<Candidate>& candidates, int inputs) {
  int lowest = -1;
  for (std::size_t c = 0; c < scored.size(); ++c) {
    if (!scored[c].model) continue;
    if (lowest < 0) {
      lowest = static_cast<int>(c);
      continue;
    }
    const auto low = static_cast<std::size_t>(lowest);
    const double a = mean_square(scored[c].validation), b = mean_square(scored[low].validation);
    if (a < b ||
        (a == b && simplicity(candidates[c], inputs) < simplicity(candidates[low], inputs)))
      lowest = static_cast<int>(c);
  }
  return lowest;
}

/// sel.best: the lowest, unless a one-standard-error guard against no compensation (when
/// listed) prefers leaving the machine alone; sets sel.none and the gain over it.
void guard_against_none(Selection& sel, const std::vector<Candidate>& candidates) {
  const auto& scored = sel.candidates;
  sel.best = sel.lowest;
  for (std::size_t c = 0; c < scored.size(); ++c) {
    if (candidates[c].spec.kind != ModelKind::no_compensation || !scored[c].model) continue;
    sel.none = static_cast<int>(c);
    break;
  }
  if (sel.none >= 0 && sel.none != sel.lowest) {
    // Per block, the gain in S² of the lowest over no compensation: its mean must exceed its
    // standard error, or the model is not shown to beat leaving the machine alone.
    const auto& low = scored[static_cast<std::size_t>(sel.lowest)].validation.s;
    const auto& none = scored[static_cast<std::size_t>(sel.none)].validation.s;
    std::vector<double> gains;
    for (std::size_t k = 0; k < low.size(); ++k)
      gains.push_back(none[k] * none[k] - low[k] * low[k]);
    const Accuracy g = accuracy(gains);
    sel.gain_over_none = g.sm;
    sel.gain_over_none_standard_error = g.s_sigma / std::sqrt(static_cast<double>(gains.size()));
    if (!(sel.gain_over_none > sel.gain_over_none_standard_error)) sel.best = sel.none;
  }
}

}  // namespace

Evaluation blocked_evaluation(const std::vector<Group>& groups, const std::vector<int>& pool,
                              const std::vector<int>& test, int target,
                              const std::vector<Candidate>& candidates) {
  if (pool.size() < 2)
    throw core::DataError(
        "cross-validated choice on " + std::to_string(pool.size()) +
        " groups: expected at least 2 (each validates once while the others fit)");
  if (candidates.empty()) throw core::DataError("cross-validated choice among no candidates");
  require_valid_split(Split{pool, {}, test}, static_cast<int>(groups.size()));
  require_consistent_groups(groups);
  Evaluation result;
  result.target = target;
  result.target_name = groups.front().target_names.at(static_cast<std::size_t>(target));
  result.fitting_groups = group_names(groups, pool);
  result.validation_groups = group_names(groups, pool);
  result.test_groups = group_names(groups, test);
  for (const auto& c : candidates) {
    result.sensor_sets.push_back(c.sensor_set);
    result.specs.push_back(c.spec);
  }
  auto& scored = result.selection.candidates;
  scored.resize(candidates.size());
  // Candidate scoring is an approved parallel loop: each candidate writes only its own slot.
  core::parallel_for(static_cast<std::ptrdiff_t>(candidates.size()), [&](std::ptrdiff_t i) {
    scored[static_cast<std::size_t>(i)] = scored_candidate(
        groups, pool, target, candidates[static_cast<std::size_t>(i)], static_cast<int>(i));
  });
  const int inputs = static_cast<int>(groups.front().input_names.size());
  auto& sel = result.selection;
  sel.lowest = lowest_candidate(scored, candidates, inputs);
  if (sel.lowest < 0)
    throw core::DataError("target " + result.target_name +
                          ": every candidate failed (first: " + scored.front().failure + ")");
  guard_against_none(sel, candidates);
  const Candidate& chosen = candidates[static_cast<std::size_t>(result.selection.best)];
  result.model =
      fitted_model(chosen.spec, group_subset(groups, pool), chosen.sensor_set.sensors, target);
  if (!test.empty()) result.test = model_accuracy(result.model, group_subset(groups, test));
  return result;
}

std::vector<Candidate> measured_data_candidates(int sensor_count, bool has_inputs, bool quick) {
  SensorSet all{"all", {}};
  for (int c = 0; c < sensor_count; ++c) all.sensors.push_back(c);
  std::vector<Candidate> out;
  ModelSpec none;
  none.kind = ModelKind::no_compensation;
  none.reject_gross_errors = false;
  out.push_back({all, none});
  out.push_back({all, ModelSpec{}});
  ModelSpec plain;
  plain.reject_gross_errors = false;
  out.push_back({all, plain});
  const std::vector<double> lambdas =
      quick ? std::vector<double>{1e-4, 1e-2, 1.0}
            : std::vector<double>{1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0};
  for (double lambda : lambdas) {
    // Ridge is not the standard's model: its shrinkage, not the 3σ criterion, guards it.
    ModelSpec ridge;
    ridge.kind = ModelKind::ridge;
    ridge.ridge_lambda = lambda;
    ridge.reject_gross_errors = false;
    out.push_back({all, ridge});
    // Heat reaches the structure through lags that the surface sensors do not show.
    ModelSpec lagged = ridge;
    lagged.kind = ModelKind::distributed_lag;
    lagged.time_constants = {600.0, 3600.0};
    lagged.use_inputs = has_inputs;
    out.push_back({all, lagged});
  }
  return out;
}

std::vector<OutOfRange> out_of_training_range(const std::vector<Group>& training,
                                              const std::vector<Group>& test) {
  require_consistent_groups(training);
  FeatureMap all;
  for (std::size_t c = 0; c < training.front().sensor_names.size(); ++c) {
    all.sensors.push_back(static_cast<int>(c));
    all.sensor_names.push_back(training.front().sensor_names[c]);
  }
  for (std::size_t c = 0; c < training.front().input_names.size(); ++c) {
    all.inputs.push_back(static_cast<int>(c));
    all.input_names.push_back(training.front().input_names[c]);
  }
  const auto range = [&](const std::vector<Group>& groups) {
    Eigen::MatrixXd lo = Eigen::RowVectorXd::Constant(
        static_cast<Eigen::Index>(all.sensors.size() + all.inputs.size()),
        std::numeric_limits<double>::infinity());
    Eigen::MatrixXd hi = -lo;
    for (const auto& g : groups) {
      const Eigen::MatrixXd x = feature_matrix(all, g);
      lo = lo.cwiseMin(x.colwise().minCoeff());
      hi = hi.cwiseMax(x.colwise().maxCoeff());
    }
    return std::pair{lo, hi};
  };
  const auto [train_lo, train_hi] = range(training);
  const std::vector<std::string> names = feature_names(all);
  std::vector<OutOfRange> out;
  for (Eigen::Index c = 0; c < train_lo.cols(); ++c) {
    const double margin = 0.05 * (train_hi(0, c) - train_lo(0, c));
    OutOfRange o;
    o.column = names[static_cast<std::size_t>(c)];
    o.training_min = train_lo(0, c);
    o.training_max = train_hi(0, c);
    o.test_min = std::numeric_limits<double>::infinity();
    o.test_max = -o.test_min;
    Eigen::Index outside = 0, samples = 0;
    for (const auto& g : test) {
      const Eigen::VectorXd x = feature_matrix(all, g).col(c);
      o.test_min = std::min(o.test_min, x.minCoeff());
      o.test_max = std::max(o.test_max, x.maxCoeff());
      outside +=
          (x.array() < o.training_min - margin || x.array() > o.training_max + margin).count();
      samples += x.size();
    }
    o.share_outside = samples ? static_cast<double>(outside) / static_cast<double>(samples) : 0.0;
    if (outside > 0) out.push_back(o);
  }
  return out;
}

}  // namespace tt::fitting
