// From a typed case to the conforming tetrahedral mesh of all its bodies, with boundary groups
// classified by the case's rules and named points pinned to vertices.
#pragma once

#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/plc.hpp"
#include "mesh/tet_mesh.hpp"

namespace tt::mesh {

struct BodyReport {
  std::string name;
  double volume = 0;         /// meshed volume [m^3]
  double exact_volume = -1;  /// analytic (or closed-surface) volume, -1 when not available [m^3]
};

struct MeshReport {
  int nodes = 0;
  int tets = 0;
  int order = 1;
  double min_dihedral_deg = 0;
  std::vector<BodyReport> bodies;
  std::vector<double> group_areas;     /// per boundary group [m^2]
  std::vector<double> point_distance;  /// per named point: distance to its node [m]
};

/// Tetrahedra a case's PLC will give, estimated before TetGen starts (an upper-side guess).
struct MeshEstimate {
  double volume_tets = 0;   /// from each body's volume at its max_edge
  double surface_tets = 0;  /// from the facets' shortest edges (fine circle_segments, slivers)
  int finest_body = -1;     /// body with the most volume tets
  double finest_body_tets = 0;
  double tets() const { return volume_tets + surface_tets; }
};
MeshEstimate mesh_estimate(const core::CaseSpec& spec, const Plc& plc);
/// The same from the spec alone (curved sides for the surface part), before the PLC is built.
MeshEstimate mesh_estimate(const core::CaseSpec& spec);

/// Throws MeshError naming mesh.max_tets, the body and the keys to change when the estimate is
/// beyond the case's mesh.max_tets.
void require_mesh_within_bounds(const core::CaseSpec& spec, const MeshEstimate& estimate);

/// Meshes the case: PLC (its size estimated and bounded), TetGen (bounded in time and memory),
/// mid-edge nodes, faces, groups, named points.
TetMesh mesh_case(const core::CaseSpec& spec);

/// Turns TetGen's linear tets into the project's mesh (order from the spec).
TetMesh assemble_mesh(const LinearTets& tets, const core::CaseSpec& spec,
                      const std::vector<int>& point_vertex);

/// Figures a report needs, computed from the mesh alone.
MeshReport mesh_report(const TetMesh& mesh, const core::CaseSpec& spec);

/// Smallest dihedral angle over all tets [deg].
double min_dihedral_deg(const TetMesh& mesh);

/// Volume of every tet [m^3] (straight-sided).
std::vector<double> tet_volumes(const TetMesh& mesh);

/// Area of every face [m^2].
std::vector<double> face_areas(const TetMesh& mesh);

/// The tolerance of the case's face selectors [m]: a face whose centroid lies within it outside a
/// selector's box (or off its plane or cylinder) still belongs to the group; 1e-7 of the diagonal
/// of the nodes' bounding box. Code that picks faces by the same boxes (calibration's heat-input
/// patches) uses it too, so that a patch and the group written for it hold the same faces.
double selection_tolerance(const NodeMatrix& nodes);

}  // namespace tt::mesh
