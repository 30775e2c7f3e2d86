// Mesh vertices on chosen surfaces: where a temperature sensor can be screwed on. Placement
// takes them as candidates when the case asks for `candidates = "surface"`.
#pragma once

#include <vector>

#include "core/ids.hpp"
#include "mesh/tet_mesh.hpp"

namespace tt::mesh {

/// Corner nodes of the exterior faces of `bodies`' tets and of every face of `groups`, ascending
/// and distinct. Interfaces between bodies are not a body's surface (a sensor cannot go there),
/// but a group may hold them. Mid-edge nodes of 10-node meshes are left out: the corner vertices
/// are the mesh's own points, the mid-edge ones only interpolation nodes.
std::vector<int> surface_vertices(const TetMesh& mesh, const std::vector<core::RegionId>& bodies,
                                  const std::vector<core::BoundaryId>& groups);

/// `count` of the `nodes` spread evenly over space by farthest-point sampling (start at the
/// first node; each next one is the node farthest from those taken, ties to the lower position),
/// ascending. All of them when count <= 0 or count >= nodes.size(). O(nodes x count).
std::vector<int> spread_subset(const TetMesh& mesh, const std::vector<int>& nodes, int count);

}  // namespace tt::mesh
