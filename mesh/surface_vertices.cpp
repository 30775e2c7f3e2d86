#include "mesh/surface_vertices.hpp"

#include <algorithm>
#include <limits>

namespace tt::mesh {

std::vector<int> surface_vertices(const TetMesh& mesh, const std::vector<core::RegionId>& bodies,
                                  const std::vector<core::BoundaryId>& groups) {
  const auto has = [](const auto& list, auto id) {
    return std::find(list.begin(), list.end(), id) != list.end();
  };
  std::vector<char> on(static_cast<std::size_t>(mesh.nodes.rows()), 0);
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    const auto fi = static_cast<std::size_t>(f);
    const bool exterior_of_body =
        mesh.face_other_tet[fi] < 0 &&
        has(bodies, mesh.tet_region[static_cast<std::size_t>(mesh.face_tet[fi])]);
    if (!exterior_of_body && !has(groups, mesh.face_group[fi])) continue;
    for (int a = 0; a < 3; ++a) on[static_cast<std::size_t>(mesh.faces(f, a))] = 1;
  }
  std::vector<int> out;
  for (std::size_t n = 0; n < on.size(); ++n)
    if (on[n]) out.push_back(static_cast<int>(n));
  return out;
}

std::vector<int> spread_subset(const TetMesh& mesh, const std::vector<int>& nodes, int count) {
  const auto n = static_cast<int>(nodes.size());
  if (count <= 0 || count >= n) return nodes;
  // Squared distance of every node to the nearest one taken so far.
  std::vector<double> gap(static_cast<std::size_t>(n), std::numeric_limits<double>::infinity());
  std::vector<int> taken;
  taken.reserve(static_cast<std::size_t>(count));
  int next = 0;
  while (static_cast<int>(taken.size()) < count) {
    taken.push_back(nodes[static_cast<std::size_t>(next)]);
    const Eigen::RowVector3d x = mesh.nodes.row(nodes[static_cast<std::size_t>(next)]);
    double farthest = -1;
    for (int i = 0; i < n; ++i) {
      auto& g = gap[static_cast<std::size_t>(i)];
      g = std::min(g, (mesh.nodes.row(nodes[static_cast<std::size_t>(i)]) - x).squaredNorm());
      if (g > farthest) farthest = g, next = i;
    }
  }
  std::sort(taken.begin(), taken.end());
  return taken;
}

}  // namespace tt::mesh
