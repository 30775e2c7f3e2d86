#include "mesh/cgal/surface_file_check.hpp"

#include <algorithm>
#include <charconv>
#include <initializer_list>
#include <limits>

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
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; };
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

/// The value of a word made only of decimal digits, or nothing (other characters, or beyond 64 bits).
std::optional<unsigned long long> plain_count(std::string_view word) {
  if (word.empty() || !std::all_of(word.begin(), word.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return std::nullopt;
  unsigned long long value = 0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || end != word.data() + word.size()) return std::nullopt;
  return value;
}

/// The numbers at the start of a line, read as a stream of doubles reads them (CGAL reads OFF
/// face lines so): one after the other, the next starting where the last ended ("0-10" is 0 and
/// -10), up to the first text that is no number.
std::vector<double> leading_numbers(std::string_view line) {
  std::vector<double> numbers;
  const char* at = line.data();
  const char* const end = line.data() + line.size();
  while (true) {
    while (at < end && (*at == ' ' || *at == '\t' || *at == '\r' || *at == '\v' || *at == '\f')) ++at;
    if (at < end && *at == '+') ++at;
    double value = 0;
    const auto [stop, error] = std::from_chars(at, end, value);
    if (error == std::errc::invalid_argument) break;
    numbers.push_back(error == std::errc() ? value : std::numeric_limits<double>::quiet_NaN());
    at = stop;
  }
  return numbers;
}

std::string quoted(std::string_view word) {
  constexpr std::size_t kShown = 40;
  std::string shown;
  for (char c : word.substr(0, kShown))
    shown += (static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7f) ? c : '?';
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
        return line_no(i) + ": element count " + quoted(w[2]) + " is not a count this file can hold";
      element = w[1];
      continue;
    }
    if (w[0] != "property") return line_no(i) + ": unknown header keyword " + quoted(w[0]);
    if (element.empty()) return line_no(i) + ": a property before any element";
    if (w.size() >= 2 && w[1] == "list") {
      if (w.size() != 5) return line_no(i) + ": 'property list' takes two types and a name";
      const bool indices = is_one_of(w[4], {"vertex_indices", "vertex_index"});
      if (!is_integer_type(w[2]) || !(is_integer_type(w[3]) || (!indices && is_real_type(w[3]))))
        return line_no(i) + ": list property " + quoted(w[4]) + " has types " + quoted(w[2]) + " " +
               quoted(w[3]) + "; counts and indices must be integers";
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

std::optional<std::string> off_problem(std::string_view text) {
  const auto lines = lines_of(text);
  // Words of each line with comments cut off; blank lines and comment lines skipped.
  struct Line {
    std::size_t index;
    std::string_view text;
    std::vector<std::string_view> words;
  };
  std::vector<Line> content;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string_view text = lines[i].substr(0, lines[i].find('#'));
    auto w = words_of(text);
    if (!w.empty()) content.push_back({i, text, std::move(w)});
  }
  if (content.empty()) return "the file is empty";
  const std::string_view keyword = content[0].words[0];
  const auto ends_with_off = keyword.size() >= 3 && keyword.substr(keyword.size() - 3) == "OFF";
  if (!ends_with_off) return "an OFF file starts with the keyword OFF (found " + quoted(keyword) + ")";
  const std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  if (prefix.find_first_not_of("STCN") != std::string_view::npos)
    return "only 3-D OFF files are read (keyword " + quoted(keyword) + ")";
  // The three counts follow the keyword, on its line or the next ones.
  std::vector<std::string_view> header;
  std::size_t row = 0, word = 1;
  if (content[0].words.size() > 1 && content[0].words[1] == "BINARY")
    return "binary OFF is not read; export ASCII OFF, STL or PLY";
  while (header.size() < 3 && row < content.size()) {
    const auto& w = content[row].words;
    while (header.size() < 3 && word < w.size()) header.push_back(w[word++]);
    if (header.size() < 3) ++row, word = 0;
  }
  if (header.size() < 3) return "the header lacks its three counts (vertices, faces, edges)";
  std::array<unsigned long long, 3> counts{};
  for (std::size_t k = 0; k < 3; ++k) {
    const auto c = plain_count(header[k]);
    if (!c || *c > text.size())
      return line_no(content[row].index) + ": count " + quoted(header[k]) +
             " is not a count this file can hold";
    counts[k] = *c;
  }
  // One vertex per line, then one face per line. CGAL reads a face line as numbers and casts the
  // first to the count of indices and the next ones to indices: the count must be a number from 0
  // to what the file can hold (each index takes at least two bytes), each index one of a vertex.
  const std::size_t first_face = row + 1 + counts[0];
  for (std::size_t f = 0; f < counts[1] && first_face + f < content.size(); ++f) {
    const auto& [line, text_of_line, w] = content[first_face + f];
    const std::vector<double> numbers = leading_numbers(text_of_line);
    if (numbers.empty()) continue;  // no number at all: CGAL refuses the line
    const double count = numbers[0];
    if (!(count >= 0 && count <= static_cast<double>(text.size() / 2)))
      return line_no(line) + ": a face of " + quoted(w[0]) +
             " vertices; a count from 0 to what this file can hold is expected";
    const auto indices = std::min(numbers.size() - 1, static_cast<std::size_t>(count));
    for (std::size_t i = 1; i <= indices; ++i)
      if (!(numbers[i] >= 0 && numbers[i] < static_cast<double>(counts[0])))
        return line_no(line) + ": a face names vertex " + std::to_string(numbers[i]) +
               "; the file has " + std::to_string(counts[0]) + " vertices";
  }
  return std::nullopt;
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

}  // namespace tt::mesh::cgal
