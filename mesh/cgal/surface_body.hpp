// Bodies given as closed triangulated surfaces (STL, OFF, PLY), and the few questions the mesher
// asks about them: is the surface a valid solid, where is a point, do two solids meet. CGAL stays
// inside surface_body.cpp (it needs -frounding-math and compiles slowly): this header exposes
// Eigen types only.
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace tt::mesh::cgal {

/// A closed triangulated surface whose triangles' right-hand normals point out of the solid.
struct TriangleSurface {
  std::vector<Eigen::Vector3d> vertices;  /// [m]
  std::vector<std::array<int, 3>> triangles;
};

/// A surface file read as a solid: one closed, 2-manifold, outward-oriented shell that does not
/// intersect itself, with positive volume.
struct SurfaceSolid {
  TriangleSurface surface;
  Eigen::Vector3d inside_point = Eigen::Vector3d::Zero();  /// strictly inside, clear of it [m]
  double volume = 0;                                       /// enclosed volume [m^3]
};

/// Reads `file` (STL, OFF or PLY), scales its coordinates by `scale` (file unit -> m) and checks
/// that it bounds a solid. A consistently inward-oriented surface is turned outward. `what` names
/// the owner in messages ("body 'tool'"). Throws GeometryError naming the file and the defect.
SurfaceSolid surface_solid(const std::filesystem::path& file, double scale,
                           const std::string& what);

/// Where a point lies with respect to a closed surface.
struct PointLocation {
  enum class Kind { outside, inside, vertex, triangle };
  Kind kind = Kind::outside;
  int index = -1;  /// vertex (Kind::vertex) or triangle (Kind::triangle) index, else -1
};

/// Per point: within `tol` [m] of a vertex, else within `tol` of a triangle, else strictly inside
/// or outside the solid `surface` bounds.
std::vector<PointLocation> locate_points(const TriangleSurface& surface,
                                         const std::vector<Eigen::Vector3d>& points, double tol);

/// True when the solids bounded by closed surfaces `a` and `b` share a point (touching counts).
bool solids_meet(const TriangleSurface& a, const TriangleSurface& b);

/// True when the solid bounded by `a` lies in the open interior of the solid bounded by `b`.
bool solid_strictly_inside(const TriangleSurface& a, const TriangleSurface& b);

}  // namespace tt::mesh::cgal
