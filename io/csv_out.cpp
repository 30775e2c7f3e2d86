#include "io/csv_out.hpp"

#include <array>
#include <charconv>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include "core/csv_cells.hpp"
#include "core/errors.hpp"
#include "core/text.hpp"
#include "io/atomic_dir.hpp"

namespace tt::io {

namespace fs = std::filesystem;

namespace {

std::vector<std::string_view> split_cells(std::string_view line) {
  std::vector<std::string_view> cells;
  for (std::size_t at = 0; at != std::string_view::npos;)
    cells.push_back(core::next_cell(line, at));
  return cells;
}

/// The file's text without a UTF-8 byte order mark.
std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw core::IoError(path.string() +
                        ": cannot open the CSV file for reading; hint: check the "
                        "path and its permissions");
  }
  std::ostringstream content;
  content << in.rdbuf();
  std::string text = content.str();
  text.erase(0, text.size() - core::without_byte_order_mark(text).size());
  return text;
}

/// The header's column names (quotes dropped); each must be non-empty and new.
std::vector<std::string> header_names(const std::vector<std::string_view>& cells,
                                      const std::string& source, int line_number) {
  std::vector<std::string> header;
  std::set<std::string> seen;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const std::string_view name = cells[c];
    if (name.empty()) {
      throw core::DataError(core::located(
          source, line_number,
          "header column " + std::to_string(c + 1) + " has no name: expected a column name"));
    }
    if (!seen.insert(std::string(name)).second) {
      throw core::DataError(core::located(source, line_number,
                                          "header column " + std::to_string(c + 1) + " '" +
                                              std::string(name) +
                                              "' repeats an earlier column name"));
    }
    header.emplace_back(name);
  }
  return header;
}

/// One data row's numbers appended to `values` (row-major): one per header column.
void append_row(const std::vector<std::string_view>& cells, const CsvTable& table, int line_number,
                std::vector<double>& values) {
  if (cells.size() != table.header.size()) {
    throw core::DataError(
        core::located(table.source, line_number,
                      "row has " + std::to_string(cells.size()) + " cells: expected " +
                          std::to_string(table.header.size()) + " (one per header column)"));
  }
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const std::optional<double> number = core::cell_number(cells[c]);
    if (!number) {
      throw core::DataError(core::located(
          table.source, line_number,
          "column " + std::to_string(c + 1) + " (" + table.header[c] + ") = '" +
              std::string(cells[c]) + "': expected a number; hint: write missing values as nan"));
    }
    values.push_back(*number);
  }
}

}  // namespace

int CsvTable::column_index(const std::string& name) const {
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (header[c] == name) return static_cast<int>(c);
  }
  throw core::DataError(
      core::located(source, 0, "no column '" + name + "'; columns are: " + core::joined(header)));
}

Eigen::VectorXd CsvTable::column(const std::string& name) const {
  return rows.col(column_index(name));
}

void write_csv(const fs::path& path, const std::vector<std::string>& header,
               const Eigen::MatrixXd& rows, int precision) {
  if (precision < 1 || precision > 17) {
    throw core::DataError(path.string() + ": CSV precision = " + std::to_string(precision) +
                          ": expected 1..17 significant digits");
  }
  if (static_cast<Eigen::Index>(header.size()) != rows.cols()) {
    throw core::DataError(path.string() + ": CSV header has " + std::to_string(header.size()) +
                          " names for " + std::to_string(rows.cols()) +
                          " columns: expected one name per column");
  }
  for (const std::string& name : header) {
    if (name.empty() || name.find_first_of(",\"\r\n") != std::string::npos ||
        core::trimmed(name) != name) {
      throw core::DataError(path.string() + ": CSV column name '" + name +
                            "': expected a non-empty name without commas, quotes, line breaks "
                            "or surrounding spaces; hint: use e.g. T02_degC");
    }
  }
  std::string text;
  text.reserve(static_cast<std::size_t>(rows.size()) * (precision + 8) + 64);
  for (std::size_t c = 0; c < header.size(); ++c) text += (c ? "," : "") + header[c];
  text += '\n';
  std::array<char, 64> buffer{};
  for (Eigen::Index r = 0; r < rows.rows(); ++r) {
    for (Eigen::Index c = 0; c < rows.cols(); ++c) {
      if (c) text += ',';
      const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), rows(r, c),
                                        std::chars_format::general, precision);
      text.append(buffer.data(), result.ptr);
    }
    text += '\n';
  }
  write_file_atomically(path, text);
}

CsvTable read_numeric_csv(const fs::path& path) {
  CsvTable table;
  table.source = path.string();
  std::vector<double> values;  // row-major
  std::size_t row_count = 0;
  std::istringstream lines(file_text(path));
  std::string line;
  int line_number = 0;
  while (std::getline(lines, line)) {
    ++line_number;
    const std::string_view content_view = core::trimmed(line);
    if (content_view.empty() || content_view.starts_with('#')) continue;
    const auto cells = split_cells(content_view);
    if (table.header.empty()) {
      table.header = header_names(cells, table.source, line_number);
      continue;
    }
    append_row(cells, table, line_number, values);
    ++row_count;
  }
  if (table.header.empty()) {
    throw core::DataError(core::located(table.source, 0,
                                        "no header line: expected column names such as "
                                        "time_s,T02_degC"));
  }
  const auto column_count = static_cast<Eigen::Index>(table.header.size());
  table.rows =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          values.data(), static_cast<Eigen::Index>(row_count), column_count);
  return table;
}

}  // namespace tt::io
