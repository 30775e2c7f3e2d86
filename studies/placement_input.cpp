#include "studies/placement_input.hpp"

#include <string>

#include "core/errors.hpp"

namespace tt::studies {

placement::PlacementInput groups_end_to_end(const std::vector<fitting::Group>& groups,
                                            const std::vector<int>& which,
                                            const Eigen::MatrixX3d& positions,
                                            Eigen::Index targets) {
  if (which.empty()) throw core::DataError("placement on groups: no group given");
  Eigen::Index rows = 0;
  for (int i : which) {
    if (i < 0 || i >= static_cast<int>(groups.size()))
      throw core::DataError("placement on groups: group " + std::to_string(i) + " of " +
                            std::to_string(groups.size()));
    if (groups[static_cast<std::size_t>(i)].sensor_names !=
        groups[static_cast<std::size_t>(which.front())].sensor_names)
      throw core::DataError("placement on groups: group '" +
                            groups[static_cast<std::size_t>(i)].name +
                            "' has other sensors than '" +
                            groups[static_cast<std::size_t>(which.front())].name + "'");
    rows += groups[static_cast<std::size_t>(i)].time.size();
  }
  const fitting::Group& g0 = groups[static_cast<std::size_t>(which.front())];
  placement::PlacementInput in;
  for (std::size_t c = 0; c < g0.sensor_names.size(); ++c)
    in.ids.push_back(core::SensorId{static_cast<int>(c) + 1});
  in.positions_m = positions;
  in.times_s.resize(rows);
  in.temperatures_K.resize(rows, g0.temperature.cols());
  Eigen::MatrixXd error(rows, targets);
  Eigen::Index r = 0;
  double offset = 0;
  for (int i : which) {
    const fitting::Group& g = groups[static_cast<std::size_t>(i)];
    const Eigen::Index n = g.time.size();
    in.times_s.segment(r, n) = g.time.array() - g.time(0) + offset;
    in.temperatures_K.middleRows(r, n) = g.temperature;
    error.middleRows(r, n) = g.error.leftCols(targets);
    offset = in.times_s(r + n - 1) + 1.0;
    r += n;
  }
  for (Eigen::Index k = 0; k < targets; ++k)
    in.targets.push_back({g0.target_names[static_cast<std::size_t>(k)], error.col(k)});
  return in;
}

}  // namespace tt::studies
