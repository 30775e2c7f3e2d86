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

/// Why an ASCII OFF file is refused, or nothing: its header counts and the leading count of every
/// face line must be plain integers that the file's size can hold. Binary OFF and the n-dimensional
/// variants are refused: only the 3-D ASCII forms are read.
std::optional<std::string> off_problem(std::string_view text);

/// Why a polygon soup is refused, or nothing: every polygon has at least 3 indices, each below
/// `point_count`.
std::optional<std::string> soup_problem(const std::vector<std::vector<std::size_t>>& polygons,
                                        std::size_t point_count);

}  // namespace tt::mesh::cgal
