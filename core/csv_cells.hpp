// The cells of a comma-separated line as every reader of the project takes them (data.csv, a
// duty-cycle or table CSV, compensate's stream): split at commas; blanks (space, tab, CR) around a
// cell dropped; one pair of double quotes around a cell dropped too, as a spreadsheet quotes its
// fields ("T07", "20.5"). A quoted field that holds a comma is not supported.
#pragma once

#include <charconv>
#include <optional>
#include <string_view>

namespace tt::core {

/// `text` without the UTF-8 byte-order mark a spreadsheet may write before a file's first cell.
inline std::string_view without_byte_order_mark(std::string_view text) {
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  return text;
}

/// `text` without blanks (space, tab, CR) at either end.
inline std::string_view trimmed(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

/// A cell's content: trimmed, and without one pair of double quotes around it.
inline std::string_view cell_content(std::string_view cell) {
  cell = trimmed(cell);
  if (cell.size() >= 2 && cell.front() == '"' && cell.back() == '"')
    cell = trimmed(cell.substr(1, cell.size() - 2));
  return cell;
}

/// The content of the cell of `line` that starts at `start`; `start` then moves past the cell's
/// comma, or to npos after the last cell. Loop: for (std::size_t at = 0; at != npos;) ...
inline std::string_view next_cell(std::string_view line, std::size_t& start) {
  const std::size_t comma = line.find(',', start);
  const std::string_view cell = cell_content(line.substr(start, comma - start));
  start = comma == std::string_view::npos ? comma : comma + 1;
  return cell;
}

/// The number a cell's content is in full (a leading '+' allowed; "nan" and "inf" give
/// non-finite values), or nullopt when it is not one number (an empty cell included).
inline std::optional<double> cell_number(std::string_view content) {
  if (content.starts_with('+')) content.remove_prefix(1);
  if (content.empty()) return std::nullopt;
  double value = 0.0;
  const auto [end, ec] = std::from_chars(content.data(), content.data() + content.size(), value);
  if (ec != std::errc() || end != content.data() + content.size()) return std::nullopt;
  return value;
}

}  // namespace tt::core
