#include "io/candidates_csv.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "core/errors.hpp"
#include "io/atomic_dir.hpp"

namespace tt::io {

namespace {

constexpr const char* kHeader = "id,node,x_m,y_m,z_m";

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

}  // namespace

void write_candidates_csv(const std::filesystem::path& path, const CandidateTable& table) {
  const auto n = table.ids.size();
  if (table.nodes.size() != n || static_cast<std::size_t>(table.positions.rows()) != n)
    throw core::DataError(path.string() + ": " + std::to_string(n) + " ids, " +
                          std::to_string(table.nodes.size()) + " nodes and " +
                          std::to_string(table.positions.rows()) +
                          " positions: expected one of each per candidate");
  std::string text = std::string(kHeader) + "\n";
  std::array<char, 32> buf{};
  for (std::size_t c = 0; c < n; ++c) {
    const std::string& id = table.ids[c];
    if (id.empty() || id.find_first_of(",\"\r\n") != std::string::npos || trimmed(id) != id)
      throw core::DataError(
          path.string() + ": candidate id '" + id +
          "': expected a non-empty id without commas, quotes, line breaks or surrounding spaces");
    text += id + "," + std::to_string(table.nodes[c]);
    for (int d = 0; d < 3; ++d) {
      // Shortest text that reads back to the same double.
      const auto r = std::to_chars(buf.data(), buf.data() + buf.size(),
                                   table.positions(static_cast<Eigen::Index>(c), d));
      text += ",";
      text.append(buf.data(), r.ptr);
    }
    text += "\n";
  }
  write_file_atomically(path, text);
}

CandidateTable read_candidates_csv(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw core::IoError(path.string() + ": cannot open the candidates file; hint: check the path");
  const std::string source = path.string();
  CandidateTable table;
  std::vector<Eigen::Vector3d> positions;
  std::set<std::string> seen;
  std::string line;
  int line_number = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++line_number;
    line = trimmed(line);
    if (line.empty() || line.front() == '#') continue;
    std::vector<std::string> cells;
    std::istringstream split(line);
    for (std::string cell; std::getline(split, cell, ',');) cells.push_back(trimmed(cell));
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    if (!header) {
      if (line != kHeader)
        throw core::DataError(core::located(source, line_number,
                                            "header '" + line + "': expected '" + kHeader + "'"));
      header = true;
      continue;
    }
    if (cells.size() != 5)
      throw core::DataError(core::located(
          source, line_number,
          "row has " + std::to_string(cells.size()) + " cells: expected 5 (" + kHeader + ")"));
    if (cells[0].empty() || !seen.insert(cells[0]).second)
      throw core::DataError(core::located(source, line_number,
                                          "id '" + cells[0] + "': expected a new, non-empty id"));
    int node = -1;
    const auto nr = std::from_chars(cells[1].data(), cells[1].data() + cells[1].size(), node);
    if (nr.ec != std::errc() || nr.ptr != cells[1].data() + cells[1].size() || node < 0)
      throw core::DataError(
          core::located(source, line_number, "node '" + cells[1] + "': expected an integer >= 0"));
    Eigen::Vector3d x;
    for (int d = 0; d < 3; ++d) {
      const std::string& cell = cells[static_cast<std::size_t>(2 + d)];
      const auto r = std::from_chars(cell.data(), cell.data() + cell.size(), x[d]);
      if (r.ec != std::errc() || r.ptr != cell.data() + cell.size() || !std::isfinite(x[d]))
        throw core::DataError(core::located(
            source, line_number,
            std::string(1, "xyz"[d]) + "_m = '" + cell + "': expected a finite number"));
    }
    table.ids.push_back(cells[0]);
    table.nodes.push_back(node);
    positions.push_back(x);
  }
  if (!header)
    throw core::DataError(
        core::located(source, 0, std::string("no header: expected '") + kHeader + "'"));
  table.positions.resize(static_cast<Eigen::Index>(positions.size()), 3);
  for (std::size_t c = 0; c < positions.size(); ++c)
    table.positions.row(static_cast<Eigen::Index>(c)) = positions[c].transpose();
  return table;
}

}  // namespace tt::io
