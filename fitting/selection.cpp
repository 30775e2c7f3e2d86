#include "fitting/selection.hpp"

#include <cmath>
#include <exception>

#include "core/errors.hpp"
#include "core/parallel.hpp"

namespace tt::fitting {

namespace {

std::vector<Group> joined(std::vector<Group> a, const std::vector<Group>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

void require_candidates(const std::vector<SensorSet>& sensor_sets,
                        const std::vector<ModelSpec>& specs) {
  if (sensor_sets.empty() || specs.empty())
    throw core::DataError("model selection over " + std::to_string(sensor_sets.size()) +
                          " sensor sets and " + std::to_string(specs.size()) +
                          " model specs; expected at least one of each");
}

}  // namespace

Selection selection_on_validation(const std::vector<Group>& fitting,
                                  const std::vector<Group>& validation, int target,
                                  const std::vector<SensorSet>& sensor_sets,
                                  const std::vector<ModelSpec>& specs) {
  require_candidates(sensor_sets, specs);
  require_consistent_groups(fitting);
  const std::size_t pairs = sensor_sets.size() * specs.size();
  if (pairs > 1 && validation.empty())
    throw core::DataError("choosing among " + std::to_string(pairs) +
                          " (sensor set, model) pairs with no validation group; hint: put at "
                          "least one run in split.validation");
  if (!validation.empty()) require_consistent_groups(joined(fitting, validation));

  Selection selection;
  selection.candidates.resize(pairs);
  // Candidate scoring is an approved parallel loop: each pair writes only its own slot and PPR
  // draws its directions from its own seed, so the result does not depend on the thread count.
  core::parallel_for(static_cast<std::ptrdiff_t>(pairs), [&](std::ptrdiff_t i) {
    CandidateResult& c = selection.candidates[static_cast<std::size_t>(i)];
    c.sensor_set = static_cast<int>(static_cast<std::size_t>(i) / specs.size());
    c.spec = static_cast<int>(static_cast<std::size_t>(i) % specs.size());
    const ModelSpec& spec = specs[static_cast<std::size_t>(c.spec)];
    const SensorSet& set = sensor_sets[static_cast<std::size_t>(c.sensor_set)];
    if (!spec.sensor_method.empty() && spec.sensor_method != set.method) {
      c.failure = "not tried: '" + model_label(spec) + "' pairs with '" + spec.sensor_method +
                  "' sensor sets only";
      return;
    }
    try {
      c.model = fitted_model(specs[static_cast<std::size_t>(c.spec)], fitting,
                             sensor_sets[static_cast<std::size_t>(c.sensor_set)].sensors, target);
      if (!validation.empty()) c.validation = model_accuracy(*c.model, validation);
    } catch (const std::exception& e) {
      c.model.reset();
      c.failure = e.what();
    }
  });
  for (std::size_t i = 0; i < pairs; ++i) {
    const CandidateResult& c = selection.candidates[i];
    if (!c.model || (!validation.empty() && !std::isfinite(c.validation.sm))) continue;
    if (selection.best < 0 ||
        c.validation.sm <
            selection.candidates[static_cast<std::size_t>(selection.best)].validation.sm)
      selection.best = static_cast<int>(i);
  }
  if (selection.best < 0)
    throw core::DataError("every (sensor set, model) pair failed to fit; the first failure: " +
                          selection.candidates.front().failure);
  return selection;
}

Evaluation evaluation(const std::vector<Group>& groups, const Split& split, int target,
                      const std::vector<SensorSet>& sensor_sets,
                      const std::vector<ModelSpec>& specs, const EvaluationOptions& options) {
  require_consistent_groups(groups);
  require_valid_split(split, static_cast<int>(groups.size()));
  Evaluation result;
  result.target = target;
  if (target < 0 || target >= static_cast<int>(groups.front().target_names.size()))
    throw core::DataError("target " + std::to_string(target) + "; expected an index in [0, " +
                          std::to_string(groups.front().target_names.size()) + ")");
  result.target_name = groups.front().target_names[static_cast<std::size_t>(target)];
  result.fitting_groups = group_names(groups, split.fitting);
  result.validation_groups = group_names(groups, split.validation);
  result.test_groups = group_names(groups, split.test);
  result.sensor_sets = sensor_sets;
  result.specs = specs;

  const std::vector<Group> fitting = group_subset(groups, split.fitting);
  const std::vector<Group> validation = group_subset(groups, split.validation);
  result.selection = selection_on_validation(fitting, validation, target, sensor_sets, specs);

  const CandidateResult& best =
      result.selection.candidates[static_cast<std::size_t>(result.selection.best)];
  if (options.refit_on_validation && !validation.empty())
    result.model =
        fitted_model(specs[static_cast<std::size_t>(best.spec)], joined(fitting, validation),
                     sensor_sets[static_cast<std::size_t>(best.sensor_set)].sensors, target);
  else
    result.model = *best.model;
  if (!split.test.empty())
    result.test = model_accuracy(result.model, group_subset(groups, split.test));
  return result;
}

std::vector<Evaluation> evaluations(const std::vector<Group>& groups, const Split& split,
                                    const std::vector<SensorSet>& sensor_sets,
                                    const std::vector<ModelSpec>& specs,
                                    const EvaluationOptions& options) {
  require_consistent_groups(groups);
  std::vector<Evaluation> results;
  for (int t = 0; t < static_cast<int>(groups.front().target_names.size()); ++t)
    results.push_back(evaluation(groups, split, t, sensor_sets, specs, options));
  return results;
}

LeaveOneGroupOut leave_one_group_out(const std::vector<Group>& groups, int target,
                                     const std::vector<SensorSet>& sensor_sets,
                                     const std::vector<ModelSpec>& specs,
                                     const EvaluationOptions& options) {
  LeaveOneGroupOut result;
  std::vector<double> s;
  for (const Split& split : leave_one_group_out_splits(static_cast<int>(groups.size()))) {
    result.folds.push_back(evaluation(groups, split, target, sensor_sets, specs, options));
    s.push_back(result.folds.back().test.s.front());
  }
  result.test = accuracy(s);
  return result;
}

std::vector<SensorSet> correlation_sensor_sets(const std::vector<Group>& groups, int target,
                                               int max_count) {
  const std::vector<int> ranked = sensors_by_correlation(groups, target, max_count);
  std::vector<SensorSet> sets;
  for (int m = 1; m <= max_count; ++m)
    sets.push_back(SensorSet{"correlation", std::vector<int>(ranked.begin(), ranked.begin() + m)});
  return sets;
}

SensorCountTable sensor_count_table(const std::vector<Group>& groups, const Split& split,
                                    int target, const std::vector<SensorSet>& sensor_sets,
                                    const std::vector<ModelSpec>& specs, double required_sm,
                                    const EvaluationOptions& options) {
  if (!(required_sm > 0.0))
    throw core::DataError("required accuracy S_M = " + std::to_string(required_sm) +
                          " m: must be > 0");
  if (split.test.empty())
    throw core::DataError("sensor count table with no test group; expected at least one");
  SensorCountTable table;
  table.required_sm = required_sm;
  table.target = target;
  for (const SensorSet& set : sensor_sets) {
    const Evaluation e = evaluation(groups, split, target, {set}, specs, options);
    const CandidateResult& best =
        e.selection.candidates[static_cast<std::size_t>(e.selection.best)];
    SensorCountRow row;
    row.method = set.method;
    row.m = static_cast<int>(set.sensors.size());
    row.model = model_label(e.model.spec);
    row.validation_sm = split.validation.empty() ? std::nan("") : best.validation.sm;
    row.test_sm = e.test.sm;
    row.test_s_sigma = e.test.s_sigma;
    table.target_name = e.target_name;
    table.rows.push_back(row);
    auto lower = [&](std::map<std::string, int>& smallest, double sm) {
      if (!(sm <= required_sm)) return;
      auto it = smallest.find(row.method);
      if (it == smallest.end() || row.m < it->second) smallest[row.method] = row.m;
    };
    lower(table.smallest_m_validation, row.validation_sm);
    lower(table.smallest_m_test, row.test_sm);
  }
  return table;
}

}  // namespace tt::fitting
