// Mirror twins: on a part symmetric about a plane x = const, a candidate and its mirror image
// carry the same information. Of each pair only the lower column enters the multi-sensor searches
// (the tie-breaking rule: the lower index wins), so a result never holds both.
#pragma once

#include <Eigen/Dense>
#include <utility>
#include <vector>

namespace tt::placement {

/// (lower, higher) column pairs whose positions mirror each other about x = plane_x_m within
/// tolerance_m. positions_m: #candidates x 3 [m]. Points on the plane have no twin.
std::vector<std::pair<int, int>> mirror_twins(const Eigen::MatrixX3d& positions_m, double plane_x_m,
                                              double tolerance_m);

/// Columns 0..candidates-1 without the higher member of each twin pair, ascending.
std::vector<int> search_pool(int candidates, const std::vector<std::pair<int, int>>& twins);

}  // namespace tt::placement
