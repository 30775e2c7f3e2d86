// The data a thermal-error model is fitted on: groups (runs) of temperature and error histories,
// and the split of a campaign's groups into fitting, validation and test groups.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace tt::fitting {

/// One run of the machine, the standard's "group" (DB3401/T 326-2024 6.2.3): every temperature
/// sensor and every thermal-error target read at the same instants.
struct Group {
  std::string name;
  /// #samples instants, strictly increasing [s]
  Eigen::VectorXd time;
  /// #samples x #sensors temperatures [K] (°C gives the same models: only increments are used)
  Eigen::MatrixXd temperature;
  /// #samples x #targets thermal errors [m]
  Eigen::MatrixXd error;
  /// #sensors names, the same in every group of a campaign
  std::vector<std::string> sensor_names;
  /// #targets names (e.g. "z", "x"), the same in every group of a campaign
  std::vector<std::string> target_names;
  /// #samples x #inputs operating inputs (spindle speed [rpm]); no columns when the runs record
  /// none
  Eigen::MatrixXd inputs;
  /// #inputs names, e.g. "speed_rpm", the same in every group of a campaign
  std::vector<std::string> input_names;
};

/// Indices into a campaign's groups. Fitting groups fit the coefficients, validation groups
/// choose the model type, its settings and the sensor set, test groups only measure the result.
struct Split {
  std::vector<int> fitting;
  std::vector<int> validation;
  std::vector<int> test;
};

/// Throws DataError unless every group is well formed (matching sizes, finite values, increasing
/// time, at least 2 samples) and all groups share sensor and target names.
void require_consistent_groups(const std::vector<Group>& groups);

/// Throws DataError unless the split's indices are in [0, group_count), no group is in two roles
/// and fitting is not empty.
void require_valid_split(const Split& split, int group_count);

/// The groups at `indices`, in that order.
std::vector<Group> group_subset(const std::vector<Group>& groups, const std::vector<int>& indices);

/// The names of the groups at `indices`.
std::vector<std::string> group_names(const std::vector<Group>& groups,
                                     const std::vector<int>& indices);

/// One split per group g of a campaign of group_count >= 3 groups: g is the test group, the next
/// group (cyclically) the validation group, all others fit.
std::vector<Split> leave_one_group_out_splits(int group_count);

/// #samples x #sensors increments ΔT_ki = T_ki − T_k0 (the standard's formula 2), each group
/// relative to its own first reading [K].
Eigen::MatrixXd temperature_increments(const Group& group, const std::vector<int>& sensors);

}  // namespace tt::fitting
