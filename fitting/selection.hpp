// Honest evaluation: the model type, its settings and the sensor set are chosen on validation
// groups only, the choice is refitted, and only then measured on test groups it has never seen.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fitting/group.hpp"
#include "fitting/metrics.hpp"
#include "fitting/models.hpp"

namespace tt::fitting {

/// Sensors chosen by one placement method for a given count m = sensors.size().
struct SensorSet {
  /// placement method, e.g. "mutual_information", "correlation"
  std::string method;
  /// temperature columns of the groups
  std::vector<int> sensors;
};

/// One (sensor set, model spec) pair fitted on the fitting groups and scored on validation.
struct CandidateResult {
  /// index into the sensor sets
  int sensor_set = 0;
  /// index into the model specs
  int spec = 0;
  /// empty when the fit failed (failure says why)
  std::optional<FittedModel> model;
  std::string failure;
  /// S per validation group, S_M, S_σ [m]
  Accuracy validation;
};

struct Selection {
  /// every pair, sensor-set major
  std::vector<CandidateResult> candidates;
  /// index into candidates of the chosen one: the smallest validation S_M (the first one on a
  /// tie, so list simpler models first), or under blocked_evaluation's rule
  int best = -1;
  /// blocked_evaluation only: the candidate of the smallest mean validation S² (ties to the fewer
  /// coefficients), the no-compensation candidate (-1 when none was listed), and the lowest one's
  /// mean per-block gain in S² over no compensation with its standard error [m²] (NaN when the
  /// lowest is no compensation or none was listed)
  int lowest = -1;
  int none = -1;
  double gain_over_none = std::numeric_limits<double>::quiet_NaN();
  double gain_over_none_standard_error = std::numeric_limits<double>::quiet_NaN();
};

/// Fits every (sensor set, spec) pair on `fitting` and scores it on `validation`. It is never
/// given the test groups, so the choice cannot depend on them. With a single pair no validation
/// groups are needed. Throws DataError when every pair fails.
Selection selection_on_validation(const std::vector<Group>& fitting,
                                  const std::vector<Group>& validation, int target,
                                  const std::vector<SensorSet>& sensor_sets,
                                  const std::vector<ModelSpec>& specs);

struct EvaluationOptions {
  /// refit the chosen candidate on fitting + validation groups before testing it
  bool refit_on_validation = true;
};

/// The outcome of choosing a model for one target and testing it.
struct Evaluation {
  int target = 0;
  std::string target_name;
  std::vector<std::string> fitting_groups;
  std::vector<std::string> validation_groups;
  std::vector<std::string> test_groups;
  std::vector<SensorSet> sensor_sets;
  std::vector<ModelSpec> specs;
  Selection selection;
  /// the chosen candidate, refitted
  FittedModel model;
  /// S per test group, S_M, S_σ [m]; empty s when the split has no test groups
  Accuracy test;
};

/// Chooses on split.validation (selection_on_validation), refits, measures on split.test.
Evaluation evaluation(const std::vector<Group>& groups, const Split& split, int target,
                      const std::vector<SensorSet>& sensor_sets,
                      const std::vector<ModelSpec>& specs, const EvaluationOptions& options = {});

/// evaluation for every target of the groups, each on its own, with the same candidates.
std::vector<Evaluation> evaluations(const std::vector<Group>& groups, const Split& split,
                                    const std::vector<SensorSet>& sensor_sets,
                                    const std::vector<ModelSpec>& specs,
                                    const EvaluationOptions& options = {});

struct LeaveOneGroupOut {
  /// fold g tests group g (leave_one_group_out_splits)
  std::vector<Evaluation> folds;
  /// S of each group when it was held out, S_M, S_σ [m]
  Accuracy test;
};

/// Every group in turn is the test group; the choice is made on the next group and the rest fit.
LeaveOneGroupOut leave_one_group_out(const std::vector<Group>& groups, int target,
                                     const std::vector<SensorSet>& sensor_sets,
                                     const std::vector<ModelSpec>& specs,
                                     const EvaluationOptions& options = {});

/// The standard's variable choice (7.1) as sensor sets: method "correlation", m = 1..max_count,
/// ranked on the given (fitting) groups.
std::vector<SensorSet> correlation_sensor_sets(const std::vector<Group>& groups, int target,
                                               int max_count);

struct SensorCountRow {
  std::string method;
  int m = 0;
  /// label of the model chosen on validation for this set
  std::string model;
  /// [m]
  double validation_sm = 0.0;
  double test_sm = 0.0;
  double test_s_sigma = 0.0;
};

/// How many sensors: one row per sensor set (model chosen on validation for each set), and per
/// method the smallest m meeting the required accuracy.
struct SensorCountTable {
  int target = 0;
  std::string target_name;
  /// required S_M [m]
  double required_sm = 0.0;
  std::vector<SensorCountRow> rows;
  /// smallest m whose validation S_M <= required_sm (the honest choice), per method; absent when
  /// no m does
  std::map<std::string, int> smallest_m_validation;
  /// smallest m whose test S_M <= required_sm, per method (a report, not a choice)
  std::map<std::string, int> smallest_m_test;
};

SensorCountTable sensor_count_table(const std::vector<Group>& groups, const Split& split,
                                    int target, const std::vector<SensorSet>& sensor_sets,
                                    const std::vector<ModelSpec>& specs, double required_sm,
                                    const EvaluationOptions& options = {});

}  // namespace tt::fitting
