#include "mesh/cgal/surface_file_check.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <optional>

namespace tt::mesh::cgal {
namespace {

bool is_one_of(std::string_view word, std::initializer_list<std::string_view> set) {
  return std::find(set.begin(), set.end(), word) != set.end();
}

bool is_integer_type(std::string_view t) {
  return is_one_of(t, {"char", "uchar", "short", "ushort", "int", "uint", "int8", "uint8", "int16",
                       "uint16", "int32", "uint32"});
}
bool is_real_type(std::string_view t) {
  return is_one_of(t, {"float", "double", "float32", "float64"});
}

/// The whitespace-separated words of one line.
std::vector<std::string_view> words_of(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  const auto blank = [](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
  };
  while (i < line.size()) {
    while (i < line.size() && blank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !blank(line[i])) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

/// The file's lines, without their '\n'.
std::vector<std::string_view> lines_of(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    lines.push_back(text.substr(at, end - at));
    at = end + 1;
  }
  return lines;
}

/// The value of a word made only of decimal digits, or nothing (other characters, or beyond 64
/// bits).
std::optional<unsigned long long> plain_count(std::string_view word) {
  if (word.empty() ||
      !std::all_of(word.begin(), word.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return std::nullopt;
  unsigned long long value = 0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || end != word.data() + word.size()) return std::nullopt;
  return value;
}

std::string quoted(std::string_view word) {
  constexpr std::size_t kShown = 40;
  std::string shown;
  for (char c : word.substr(0, kShown))
    shown +=
        (static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7f) ? c : '?';
  return "'" + shown + (word.size() > kShown ? "...'" : "'");
}

std::string line_no(std::size_t index) {
  return "line " + std::to_string(index + 1);
}

}  // namespace

std::optional<std::string> ply_header_problem(std::string_view text) {
  // The header ends at the first line whose first word is exactly "end_header" (a word that only
  // begins so, "end_header0...", does not end it); only the first megabyte is split into lines,
  // since the body of a binary file is no text.
  constexpr std::size_t kLongestHeader = 1 << 20;
  const auto lines = lines_of(text.substr(0, kLongestHeader));
  if (lines.empty() || words_of(lines[0]) != std::vector<std::string_view>{"ply"})
    return "a PLY file starts with the line 'ply'";
  std::string_view element;
  bool vertex_x = false, vertex_y = false, vertex_z = false;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto w = words_of(lines[i]);
    if (w.empty()) return line_no(i) + ": an empty line inside the header";
    if (w[0] == "end_header") {
      if (!(vertex_x && vertex_y && vertex_z))
        return "the header declares no vertex element with properties x, y and z";
      return std::nullopt;
    }
    if (is_one_of(w[0], {"format", "comment", "obj_info"})) continue;
    if (w[0] == "element") {
      if (w.size() != 3) return line_no(i) + ": 'element' takes a name and a count";
      const auto count = plain_count(w[2]);
      if (!count || *count > text.size())
        return line_no(i) + ": element count " + quoted(w[2]) +
               " is not a count this file can hold";
      element = w[1];
      continue;
    }
    if (w[0] != "property") return line_no(i) + ": unknown header keyword " + quoted(w[0]);
    if (element.empty()) return line_no(i) + ": a property before any element";
    if (w.size() >= 2 && w[1] == "list") {
      if (w.size() != 5) return line_no(i) + ": 'property list' takes two types and a name";
      // CGAL reads vertex x, y, z as scalars: a list of that name leaves its reader null.
      if (element == "vertex" && is_one_of(w[4], {"x", "y", "z"}))
        return line_no(i) + ": vertex coordinate " + quoted(w[4]) + " declared as a list";
      const bool indices = is_one_of(w[4], {"vertex_indices", "vertex_index"});
      if (!is_integer_type(w[2]) || !(is_integer_type(w[3]) || (!indices && is_real_type(w[3]))))
        return line_no(i) + ": list property " + quoted(w[4]) + " has types " + quoted(w[2]) + " " +
               quoted(w[3]) + "; counts and indices must be integers";
      // CGAL sizes a list by its count before reading it: a 32-bit count of 4e9 asks for 16 GB.
      // An 8-bit count (what exporters write) bounds a list to 255 entries.
      if (!is_one_of(w[2], {"char", "uchar", "int8", "uint8"}))
        return line_no(i) + ": list property " + quoted(w[4]) + " has a count of type " +
               quoted(w[2]) + "; only 8-bit counts (uchar) are read";
      continue;
    }
    if (w.size() != 3) return line_no(i) + ": 'property' takes a type and a name";
    const bool coordinate = element == "vertex" && is_one_of(w[2], {"x", "y", "z"});
    if (coordinate ? !is_real_type(w[1]) : !is_integer_type(w[1]) && !is_real_type(w[1]))
      return line_no(i) + ": property " + quoted(w[2]) + " has type " + quoted(w[1]) +
             (coordinate ? "; vertex coordinates must be float or double" : ", not a PLY type");
    if (element == "vertex") {
      vertex_x = vertex_x || w[2] == "x";
      vertex_y = vertex_y || w[2] == "y";
      vertex_z = vertex_z || w[2] == "z";
    }
  }
  return "the header has no 'end_header' line";
}

namespace {

/// Words of the OFF text after the keyword, each with its line, '#' comments left out, and the
/// records (rest of a line from a word) that the vertices and faces are read from.
struct OffCursor {
  std::string_view text;
  std::size_t at = 0;
  std::size_t line = 0;

  static bool blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || c == '\n';
  }

  /// Skips blanks, line ends and comments; false at the end of the text.
  bool skip() {
    while (at < text.size()) {
      if (text[at] == '\n') {
        ++line, ++at;
      } else if (blank(text[at])) {
        ++at;
      } else if (text[at] == '#') {
        while (at < text.size() && text[at] != '\n') ++at;
      } else {
        return true;
      }
    }
    return false;
  }
  std::string_view word() {
    if (!skip()) return {};
    const std::size_t start = at;
    while (at < text.size() && !blank(text[at]) && text[at] != '#') ++at;
    return text.substr(start, at - start);
  }
  /// The words from here to the end of the line (comment cut off).
  std::vector<std::string_view> record() {
    if (!skip()) return {};
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string_view rest = text.substr(at, end - at);
    at = end;
    return words_of(rest.substr(0, rest.find('#')));
  }
};

std::optional<double> finite_number(std::string_view word) {
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  double value = 0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || end != word.data() + word.size() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

}  // namespace

OffReading read_off(std::string_view text) {
  OffReading r;
  OffCursor in{text};
  const auto fail = [&](const std::string& why) {
    r.soup = {};
    r.problem = line_no(in.line) + ": " + why;
    return r;
  };
  const std::string_view keyword = in.word();
  if (keyword.empty()) return fail("the file is empty");
  if (!is_one_of(keyword, {"OFF", "COFF", "NOFF", "CNOFF", "STOFF", "STCOFF", "STNOFF", "STCNOFF"}))
    return fail("an OFF file starts with the keyword OFF (or COFF, NOFF, STOFF...), found " +
                quoted(keyword) + "; binary, homogeneous and n-dimensional OFF are not read");
  std::array<unsigned long long, 3> counts{};
  for (auto& count : counts) {
    const std::string_view w = in.word();
    if (w == "BINARY") return fail("binary OFF is not read; export ASCII OFF, STL or PLY");
    const auto c = plain_count(w);
    if (!c || *c > text.size())
      return fail("count " + quoted(w) +
                  " is not a count this file can hold (vertices, faces, edges)");
    count = *c;
  }
  const auto vertices = static_cast<std::size_t>(counts[0]),
             faces = static_cast<std::size_t>(counts[1]);
  r.soup.points.reserve(vertices);
  for (std::size_t v = 0; v < vertices; ++v) {
    const auto w = in.record();
    if (w.size() < 3)
      return fail("vertex " + std::to_string(v) + " of " + std::to_string(vertices) +
                  " lacks x, y, z");
    std::array<double, 3> p{};
    for (int k = 0; k < 3; ++k) {
      const auto x = finite_number(w[k]);
      if (!x)
        return fail("vertex " + std::to_string(v) + ": coordinate " + quoted(w[k]) +
                    " is not a finite number");
      p[k] = *x;
    }
    r.soup.points.push_back(p);
  }
  r.soup.polygons.reserve(faces);
  for (std::size_t f = 0; f < faces; ++f) {
    const auto w = in.record();
    const auto k = w.empty() ? std::nullopt : plain_count(w[0]);
    if (!k || *k < 3 || *k >= w.size())
      return fail("face " + std::to_string(f) + " of " + std::to_string(faces) +
                  ": expected a count of at least 3 and that many vertex indices, found " +
                  (w.empty() ? std::string("nothing") : quoted(w[0])));
    std::vector<std::size_t> polygon;
    polygon.reserve(*k);
    for (std::size_t i = 1; i <= *k; ++i) {
      const auto index = plain_count(w[i]);
      if (!index || *index >= vertices)
        return fail("face " + std::to_string(f) + ": vertex index " + quoted(w[i]) +
                    ", the file has " + std::to_string(vertices) + " vertices");
      polygon.push_back(static_cast<std::size_t>(*index));
    }
    r.soup.polygons.push_back(std::move(polygon));
  }
  return r;
}

std::optional<std::string> soup_problem(const std::vector<std::vector<std::size_t>>& polygons,
                                        std::size_t point_count) {
  for (std::size_t p = 0; p < polygons.size(); ++p) {
    const auto& polygon = polygons[p];
    if (polygon.size() < 3)
      return "polygon " + std::to_string(p) + " has " + std::to_string(polygon.size()) +
             " vertices, at least 3 are needed";
    for (const std::size_t index : polygon)
      if (index >= point_count)
        return "polygon " + std::to_string(p) + " names vertex " + std::to_string(index) +
               " but the file has " + std::to_string(point_count) + " vertices";
  }
  return std::nullopt;
}

namespace {

using Vec = Eigen::Vector3d;

/// Why the polygon (indices valid, at least 4) cannot be split as a fan, or nothing.
std::optional<std::string> fan_problem(const std::vector<Vec>& corner) {
  const std::size_t n = corner.size();
  Vec normal = Vec::Zero();  // Newell's normal: twice the area vector
  double size = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec& a = corner[i];
    const Vec& b = corner[(i + 1) % n];
    normal += Vec((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                  (a.x() - b.x()) * (a.y() + b.y()));
    size = std::max(size, (b - a).norm());
  }
  const double twice_area = normal.norm();
  if (!(size > 0) || !(twice_area > 1e-12 * size * size)) return std::string("has no area");
  const Vec unit = normal / twice_area;
  for (std::size_t i = 1; i < n; ++i)
    if (std::abs((corner[i] - corner[0]).dot(unit)) > 1e-6 * size)
      return "is not flat (vertex " + std::to_string(i) + " lies off the plane of the others)";
  for (std::size_t i = 0; i < n; ++i) {
    const Vec turn =
        (corner[(i + 1) % n] - corner[i]).cross(corner[(i + 2) % n] - corner[(i + 1) % n]);
    if (!(turn.dot(unit) > 1e-9 * size * size))
      return "is not strictly convex (corner " + std::to_string((i + 1) % n) +
             " is straight or turns back)";
  }
  return std::nullopt;
}

}  // namespace

Triangulation fan_triangulated(const std::vector<std::array<double, 3>>& points,
                               const std::vector<std::vector<std::size_t>>& polygons) {
  Triangulation out;
  out.triangles.reserve(polygons.size());
  for (std::size_t p = 0; p < polygons.size(); ++p) {
    const auto& polygon = polygons[p];
    if (polygon.size() == 3) {
      out.triangles.push_back(polygon);
      continue;
    }
    auto sorted = polygon;
    std::sort(sorted.begin(), sorted.end());
    std::optional<std::string> problem;
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
      problem = "names a vertex twice";
    } else {
      std::vector<Vec> corner;
      for (const std::size_t v : polygon) corner.push_back(Vec(points[v].data()));
      problem = fan_problem(corner);
    }
    if (problem) {
      out.triangles.clear();
      out.problem = "polygon " + std::to_string(p) + " (" + std::to_string(polygon.size()) +
                    " vertices) " + *problem + "; only flat convex polygons are split into " +
                    "triangles here";
      return out;
    }
    for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
      out.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
  }
  return out;
}

}  // namespace tt::mesh::cgal
