#include "placement/twins.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace tt::placement {

namespace {

using Cell = std::array<std::int64_t, 3>;

struct CellHash {
  std::size_t operator()(const Cell& c) const {
    std::uint64_t h = 1469598103934665603ull;
    for (const auto v : c) h = (h ^ static_cast<std::uint64_t>(v)) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};

}  // namespace

// Thousands of surface-vertex candidates make the all-pairs search (O(n²)) slow; points are
// binned into cubes at least `tolerance_m` wide, so an image's twin lies in one of the 27 cubes
// around it. The answer is the all-pairs one: for each i, the lowest j > i within tolerance.
std::vector<std::pair<int, int>> mirror_twins(const Eigen::MatrixX3d& positions_m, double plane_x_m,
                                              double tolerance_m) {
  const auto n = static_cast<int>(positions_m.rows());
  std::vector<std::pair<int, int>> pairs;
  if (n == 0) return pairs;
  // A non-finite position has no twin (every comparison with it fails).
  std::vector<char> finite(static_cast<std::size_t>(n));
  double extent = std::abs(plane_x_m);
  for (int i = 0; i < n; ++i) {
    finite[static_cast<std::size_t>(i)] = positions_m.row(i).allFinite();
    if (finite[static_cast<std::size_t>(i)])
      extent = std::max(extent, positions_m.row(i).cwiseAbs().maxCoeff());
  }
  // Wide enough that cube indices stay far inside int64 for any coordinates.
  const double width = std::max({1.000001 * tolerance_m, 1e-12 * extent, 1e-300});
  const auto cell_of = [&](const Eigen::RowVector3d& x) {
    return Cell{static_cast<std::int64_t>(std::floor(x(0) / width)),
                static_cast<std::int64_t>(std::floor(x(1) / width)),
                static_cast<std::int64_t>(std::floor(x(2) / width))};
  };
  std::unordered_map<Cell, std::vector<int>, CellHash> cells;
  for (int i = 0; i < n; ++i)
    if (finite[static_cast<std::size_t>(i)]) cells[cell_of(positions_m.row(i))].push_back(i);

  for (int i = 0; i < n; ++i) {
    if (!finite[static_cast<std::size_t>(i)] ||
        std::abs(positions_m(i, 0) - plane_x_m) <= tolerance_m)
      continue;
    Eigen::RowVector3d image = positions_m.row(i);
    image(0) = 2.0 * plane_x_m - image(0);
    if (!image.allFinite()) continue;
    const Cell centre = cell_of(image);
    int best = -1;
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = cells.find({centre[0] + dx, centre[1] + dy, centre[2] + dz});
          if (it == cells.end()) continue;
          for (const int j : it->second)
            if (j > i && (best < 0 || j < best) &&
                (positions_m.row(j) - image).cwiseAbs().maxCoeff() <= tolerance_m)
              best = j;
        }
    if (best >= 0) pairs.emplace_back(i, best);
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
