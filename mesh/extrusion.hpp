// Bodies built from z-parallel primitives (boxes, cylinders, annuli; union and subtraction) turned
// into one conforming PLC. Every cross-section boundary of every body is put into one planar
// straight-line graph; its faces, extruded between consecutive z breakpoints, are cells that lie
// wholly inside one body or in empty space. Facets go where the body changes across a cell face,
// so shared faces between bodies are one facet and the mesh conforms by construction. Bodies read
// from surface files stand apart and bring their own triangles.
#pragma once

#include <vector>

#include "core/case_spec.hpp"
#include "mesh/plc.hpp"

namespace tt::mesh {

/// The PLC of all bodies and, per named point of the case, how it was made a vertex.
struct ExtrudedPlc {
  Plc plc;
  std::vector<int> point_vertex;  /// per named point: PLC vertex index, or -1 if inserted inside
};

/// Radius of the regular n-gon with the same area as a circle of radius r: faceted bodies keep
/// their exact volume whatever n is.
double faceted_radius(double r, int n);

/// The vertices (counter-clockwise) of the faceted circle used for every cylinder and annulus.
std::vector<Eigen::Vector2d> faceted_circle(const Eigen::Vector2d& centre, double r, int n);

/// Builds the PLC. A body whose one `add` entry is a surface file (STL/OFF/PLY) contributes its
/// triangles as facets instead (mesh/cgal/); it must not touch any other body, and named points on
/// or in it become its vertices or interior points. Throws GeometryError for overlapping bodies,
/// invalid surface files and points outside every body.
ExtrudedPlc extruded_plc(const core::CaseSpec& spec);

/// True when point p lies inside z-extruded body b (boundary counts as inside), with faceted
/// circles. Throws GeometryError for a surface-file body.
bool body_contains(const core::Body& body, const Eigen::Vector3d& p, int circle_segments);

/// The exact (analytic) volume of a body when its subtractions lie inside its single added
/// primitive and do not overlap each other, or the volume its closed surface encloses for a
/// surface-file body; negative when it cannot be computed this way.
double exact_body_volume(const core::Body& body);

}  // namespace tt::mesh
