#include "fitting/group.hpp"

#include <set>
#include <string>

#include "core/errors.hpp"

namespace tt::fitting {

namespace {

std::string group_label(const Group& group, std::size_t index) {
  return "group " + std::to_string(index) + " '" + group.name + "'";
}

}  // namespace

void require_consistent_groups(const std::vector<Group>& groups) {
  if (groups.empty()) throw core::DataError("groups: none given; expected at least one run");
  const Group& first = groups.front();
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const Group& group = groups[g];
    const std::string label = group_label(group, g);
    const Eigen::Index n = group.time.size();
    if (n < 2)
      throw core::DataError(label + ": " + std::to_string(n) +
                            " samples; expected at least 2 (one run of several hours)");
    if (group.temperature.rows() != n || group.error.rows() != n)
      throw core::DataError(label + ": " + std::to_string(n) + " times but " +
                            std::to_string(group.temperature.rows()) + " temperature rows and " +
                            std::to_string(group.error.rows()) +
                            " error rows; expected one row per time");
    if (static_cast<std::size_t>(group.temperature.cols()) != group.sensor_names.size())
      throw core::DataError(label + ": " + std::to_string(group.temperature.cols()) +
                            " temperature columns but " +
                            std::to_string(group.sensor_names.size()) + " sensor names");
    if (static_cast<std::size_t>(group.error.cols()) != group.target_names.size())
      throw core::DataError(label + ": " + std::to_string(group.error.cols()) +
                            " error columns but " + std::to_string(group.target_names.size()) +
                            " target names");
    if (group.sensor_names != first.sensor_names)
      throw core::DataError(label + ": sensor names differ from those of group 0 '" + first.name +
                            "'; hint: every run of a campaign must list the same sensors in the "
                            "same order");
    if (group.target_names != first.target_names)
      throw core::DataError(label + ": target names differ from those of group 0 '" + first.name +
                            "'");
    if (static_cast<std::size_t>(group.inputs.cols()) != group.input_names.size() ||
        (group.inputs.cols() > 0 && group.inputs.rows() != n))
      throw core::DataError(label + ": " + std::to_string(group.inputs.rows()) + " x " +
                            std::to_string(group.inputs.cols()) + " inputs with " +
                            std::to_string(group.input_names.size()) +
                            " input names; expected one row per time and one name per column");
    if (group.input_names != first.input_names)
      throw core::DataError(label + ": inputs differ from those of group 0 '" + first.name +
                            "'; hint: give every run the same inputs (or none)");
    if (!group.inputs.allFinite())
      throw core::DataError(label + ": an input holds NaN or an infinite value");
    if (!group.time.allFinite() || !group.temperature.allFinite() || !group.error.allFinite())
      throw core::DataError(label +
                            ": contains NaN or infinite values; hint: drop or interpolate "
                            "missing readings before fitting");
    for (Eigen::Index i = 1; i < n; ++i)
      if (!(group.time(i) > group.time(i - 1)))
        throw core::DataError(label + ": time[" + std::to_string(i) +
                              "] = " + std::to_string(group.time(i)) + " s is not after time[" +
                              std::to_string(i - 1) + "] = " + std::to_string(group.time(i - 1)) +
                              " s; expected strictly increasing times");
  }
}

void require_valid_split(const Split& split, int group_count) {
  std::set<int> seen;
  auto check = [&](const std::vector<int>& role, const char* role_name) {
    for (int g : role) {
      if (g < 0 || g >= group_count)
        throw core::DataError(std::string("split.") + role_name + " holds group " +
                              std::to_string(g) + "; expected an index in [0, " +
                              std::to_string(group_count) + ")");
      if (!seen.insert(g).second)
        throw core::DataError(std::string("split.") + role_name + " holds group " +
                              std::to_string(g) +
                              " which already has another role; a group is fitting, validation "
                              "or test, never two of them");
    }
  };
  check(split.fitting, "fitting");
  check(split.validation, "validation");
  check(split.test, "test");
  if (split.fitting.empty())
    throw core::DataError("split.fitting is empty; expected at least one fitting group");
}

std::vector<Group> group_subset(const std::vector<Group>& groups, const std::vector<int>& indices) {
  std::vector<Group> subset;
  subset.reserve(indices.size());
  for (int g : indices) subset.push_back(groups.at(static_cast<std::size_t>(g)));
  return subset;
}

std::vector<std::string> group_names(const std::vector<Group>& groups,
                                     const std::vector<int>& indices) {
  std::vector<std::string> names;
  for (int g : indices) names.push_back(groups.at(static_cast<std::size_t>(g)).name);
  return names;
}

std::vector<Split> leave_one_group_out_splits(int group_count) {
  if (group_count < 3)
    throw core::DataError("leave-one-group-out over " + std::to_string(group_count) +
                          " groups; expected at least 3 (one test, one validation, one fitting)");
  std::vector<Split> splits;
  for (int g = 0; g < group_count; ++g) {
    Split split;
    split.test = {g};
    split.validation = {(g + 1) % group_count};
    for (int f = 0; f < group_count; ++f)
      if (f != g && f != split.validation.front()) split.fitting.push_back(f);
    splits.push_back(split);
  }
  return splits;
}

Eigen::MatrixXd temperature_increments(const Group& group, const std::vector<int>& sensors) {
  Eigen::MatrixXd increments(group.temperature.rows(), static_cast<Eigen::Index>(sensors.size()));
  for (std::size_t k = 0; k < sensors.size(); ++k) {
    const int s = sensors[k];
    if (s < 0 || s >= group.temperature.cols())
      throw core::DataError("sensor column " + std::to_string(s) + " in group '" + group.name +
                            "'; expected a column in [0, " +
                            std::to_string(group.temperature.cols()) + ")");
    const auto column = group.temperature.col(s);
    increments.col(static_cast<Eigen::Index>(k)) = column.array() - column(0);
  }
  return increments;
}

}  // namespace tt::fitting
