#pragma once
// Checks made on a surface file before CGAL 5.5's readers see it, and on the polygon soup they
// return. CGAL trusts its input: a PLY header it does not expect, a face that names a vertex that
// was never read, or an OFF count larger than the file can hold crash or exhaust memory inside the
// library (docs/reliability.md, findings F4 to F7). Pure functions on text and indices, no CGAL.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tt::mesh::cgal {

/// Why a PLY header is refused, or nothing when it holds only what the reader handles: `ply`,
/// `format`, `comment`, `obj_info`, `element NAME COUNT`, `property TYPE NAME` (vertex x, y, z of
/// a floating type) and `property list INT INT NAME`, every property after an element, ended by
/// `end_header`, each count no larger than the file can hold.
std::optional<std::string> ply_header_problem(std::string_view text);

/// A surface as a soup: points and polygons of point indices.
struct PolygonSoup {
  std::vector<std::array<double, 3>> points;
  std::vector<std::vector<std::size_t>> polygons;
};

/// An ASCII OFF file read into a soup, or why it cannot be: CGAL 5.5's OFF scanner casts counts
/// and indices read as doubles to integers (undefined behaviour on negative or huge values) and
/// sizes vectors by them, so OFF is read here instead, strictly. The keyword (OFF with the
/// optional ST, C, N prefixes; binary and n-dimensional variants are refused), then the vertex,
/// face and edge counts, then one vertex per record (x y z, then anything such as colours), then
/// one face per record (k, then k vertex indices, then anything). A record is the rest of a line
/// from its first non-blank character, '#' starting a comment; every count and index must be a
/// plain integer in range, every coordinate a finite number.
struct OffReading {
  PolygonSoup soup;
  std::string problem;  /// empty when read
};
OffReading read_off(std::string_view text);

/// Why a polygon soup is refused, or nothing: every polygon has at least 3 indices, each below
/// `point_count`.
std::optional<std::string> soup_problem(const std::vector<std::vector<std::size_t>>& polygons,
                                        std::size_t point_count);

/// The soup's polygons as triangles, or why they cannot be split here. A triangle stays as it is;
/// a polygon of more vertices must be flat and strictly convex (no repeated vertex, no reflex or
/// straight corner, every vertex within 1e-6 of its size from its plane) and is split as a fan
/// from its first vertex. CGAL 5.5's own triangulation of polygon faces dereferences a null face
/// on degenerate polygons (docs/reliability.md, F15), so it is never called.
struct Triangulation {
  std::vector<std::vector<std::size_t>> triangles;
  std::string problem;  /// empty when split
};
Triangulation fan_triangulated(const std::vector<std::array<double, 3>>& points,
                               const std::vector<std::vector<std::size_t>>& polygons);

}  // namespace tt::mesh::cgal
