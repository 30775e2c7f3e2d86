// The conforming tetrahedral mesh of all bodies: the value that flows from meshing to the solvers
// and the VTK writers.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/ids.hpp"

namespace tt::mesh {

using NodeMatrix = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using IndexMatrix = Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// A named point of the case (a sensor candidate, the TCP, a probe point) and the mesh vertex that
/// sits exactly at it.
struct NamedNode {
  std::string id;
  Eigen::Vector3d position;  /// [m]
  int node = -1;             /// index into TetMesh::nodes
};

/// Tetrahedra of order 1 (4 nodes) or 2 (10 nodes) in VTK's node order: corners 0..3, then
/// mid-edge nodes on edges (0,1) (1,2) (0,2) (0,3) (1,3) (2,3).
/// Surface faces are triangles with 3 or 6 nodes in VTK's order: corners 0..2, then mid-edge
/// nodes on (0,1) (1,2) (2,0); their normal (right hand) points out of `face_tet`.
struct TetMesh {
  int order = 1;
  NodeMatrix nodes;                        /// #nodes x 3 coordinates [m]; corner nodes come first
  int corner_count = 0;                    /// nodes [0, corner_count) are tet corners
  IndexMatrix tets;                        /// #tets x (4|10)
  std::vector<core::RegionId> tet_region;  /// per tet: index of its body
  std::vector<std::string> region_names;   /// per region: the body's name

  IndexMatrix faces;                         /// #faces x (3|6): exterior faces and body interfaces
  std::vector<int> face_tet;                 /// per face: the tet it bounds
  std::vector<int> face_other_tet;           /// per face: the tet across it, -1 on the exterior
  std::vector<core::BoundaryId> face_group;  /// per face: boundary group, -1 for none
  std::vector<std::string> group_names;      /// per boundary group: its name

  std::vector<NamedNode> points;

  int nodes_per_tet() const { return order == 1 ? 4 : 10; }
  int nodes_per_face() const { return order == 1 ? 3 : 6; }
};

/// The node of named point `id`, -1 when the mesh has no such point.
int named_node(const TetMesh& mesh, const std::string& id);

}  // namespace tt::mesh
