// A piecewise linear complex: the watertight, conforming input the tetrahedral mesher needs.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

namespace tt::mesh {

/// A planar facet: polygons (rings of vertex indices; a one-vertex polygon is a point that must
/// become a mesh vertex) and hole points lying strictly inside holes of the facet.
struct PlcFacet {
  std::vector<std::vector<int>> polygons;
  std::vector<Eigen::Vector3d> holes;  /// [m]
};

/// A point inside one connected part of a body: every tet reached from it gets `region`.
struct PlcRegion {
  Eigen::Vector3d point;  /// [m]
  int region = 0;         /// body index
  double max_volume = 0;  /// [m^3]
};

struct Plc {
  std::vector<Eigen::Vector3d> vertices;  /// [m]
  std::vector<PlcFacet> facets;
  std::vector<PlcRegion> regions;
  std::vector<Eigen::Vector3d> holes;            /// points in enclosed empty space [m]
  std::vector<Eigen::Vector3d> interior_points;  /// points inside bodies that must be vertices [m]
};

/// Typed options for the mesher; the adapter turns them into TetGen switches.
struct TetgenOptions {
  double radius_edge_ratio = 1.5;
  double min_dihedral_deg = 12.0;
  double time_limit_s = 3600;  /// wall time TetGen may take; then it is ended (MeshError)
  double memory_limit_GB = 8;  /// address space TetGen may add to what it inherits [10^9 B]
};

/// What the tetrahedraliser returns: linear tets (positively oriented) and their regions.
struct LinearTets {
  std::vector<Eigen::Vector3d> nodes;  /// [m]; the PLC's vertices keep their indices
  std::vector<std::array<int, 4>> tets;
  std::vector<int> region;  /// per tet: body index
};

}  // namespace tt::mesh
