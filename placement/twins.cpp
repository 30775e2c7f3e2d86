#include "placement/twins.hpp"

#include <algorithm>

namespace tt::placement {

std::vector<std::pair<int, int>> mirror_twins(const Eigen::MatrixX3d& positions_m, double plane_x_m,
                                              double tolerance_m) {
  std::vector<std::pair<int, int>> pairs;
  const auto n = static_cast<int>(positions_m.rows());
  for (int i = 0; i < n; ++i) {
    if (std::abs(positions_m(i, 0) - plane_x_m) <= tolerance_m) continue;
    Eigen::RowVector3d image = positions_m.row(i);
    image(0) = 2.0 * plane_x_m - image(0);
    for (int j = i + 1; j < n; ++j)
      if ((positions_m.row(j) - image).cwiseAbs().maxCoeff() <= tolerance_m) {
        pairs.emplace_back(i, j);
        break;
      }
  }
  return pairs;
}

std::vector<int> search_pool(int candidates, const std::vector<std::pair<int, int>>& twins) {
  std::vector<char> dropped(static_cast<std::size_t>(candidates), 0);
  for (const auto& [lower, higher] : twins)
    if (higher >= 0 && higher < candidates) dropped[static_cast<std::size_t>(higher)] = 1;
  std::vector<int> pool;
  for (int c = 0; c < candidates; ++c)
    if (!dropped[static_cast<std::size_t>(c)]) pool.push_back(c);
  return pool;
}

}  // namespace tt::placement
