#include "fitting/segments.hpp"

#include <cmath>
#include <limits>

#include "core/errors.hpp"

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
  return s;
}

std::vector<Group> segment_groups(const std::vector<Segment>& segments) {
  std::vector<Group> groups;
  for (const auto& s : segments) groups.push_back(s.group);
  return groups;
}

Evaluation cross_validated_evaluation(const std::vector<Group>& groups,
                                      const std::vector<int>& pool, const std::vector<int>& test,
                                      int target, const std::vector<SensorSet>& sensor_sets,
                                      const std::vector<ModelSpec>& specs) {
  if (pool.size() < 2)
    throw core::DataError(
        "cross-validated choice on " + std::to_string(pool.size()) +
        " groups: expected at least 2 (each validates once while the others fit)");
  require_valid_split(Split{pool, {}, test}, static_cast<int>(groups.size()));
  require_consistent_groups(groups);
  Evaluation result;
  result.target = target;
  result.target_name = groups.front().target_names.at(static_cast<std::size_t>(target));
  result.fitting_groups = group_names(groups, pool);
  result.validation_groups = group_names(groups, pool);
  result.test_groups = group_names(groups, test);
  result.sensor_sets = sensor_sets;
  result.specs = specs;

  std::vector<std::vector<double>> s;  // per candidate, validation S of each fold
  std::vector<std::string> failure;
  for (std::size_t k = 0; k < pool.size(); ++k) {
    std::vector<int> fit;
    for (std::size_t j = 0; j < pool.size(); ++j)
      if (j != k) fit.push_back(pool[j]);
    const Selection fold = selection_on_validation(
        group_subset(groups, fit), group_subset(groups, {pool[k]}), target, sensor_sets, specs);
    if (k == 0) {
      result.selection.candidates = fold.candidates;
      s.resize(fold.candidates.size());
      failure.resize(fold.candidates.size());
    }
    for (std::size_t c = 0; c < fold.candidates.size(); ++c) {
      const auto& candidate = fold.candidates[c];
      if (!candidate.model) {
        failure[c] = candidate.failure;
        continue;
      }
      if (!candidate.validation.s.empty()) s[c].push_back(candidate.validation.s.front());
    }
  }
  double best_sm = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < s.size(); ++c) {
    auto& candidate = result.selection.candidates[c];
    if (!failure[c].empty() || s[c].size() != pool.size()) {
      candidate.model.reset();
      candidate.failure = failure[c].empty() ? "no validation score in some fold" : failure[c];
      continue;
    }
    candidate.validation = accuracy(s[c]);
    if (candidate.validation.sm < best_sm) {
      best_sm = candidate.validation.sm;
      result.selection.best = static_cast<int>(c);
    }
  }
  if (result.selection.best < 0)
    throw core::DataError("target " + result.target_name +
                          ": every (sensor set, model) pair failed in some fold");
  const auto& best = result.selection.candidates[static_cast<std::size_t>(result.selection.best)];
  result.model =
      fitted_model(specs[static_cast<std::size_t>(best.spec)], group_subset(groups, pool),
                   sensor_sets[static_cast<std::size_t>(best.sensor_set)].sensors, target);
  if (!test.empty()) result.test = model_accuracy(result.model, group_subset(groups, test));
  return result;
}

}  // namespace tt::fitting
