// Plain numeric CSV tables at the edge: one header line of column names (with their units, e.g.
// `time_s,T02_degC`) and rows of numbers. Written atomically; read back with errors that name the
// file, line and column.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace tt::io {

/// A numeric table read from a CSV file.
struct CsvTable {
  std::string source;               /// the file it was read from, for messages
  std::vector<std::string> header;  /// column names
  Eigen::MatrixXd rows;             /// #rows x #columns

  /// Index of column `name`; throws DataError listing the columns when there is none.
  int column_index(const std::string& name) const;
  /// The values of column `name` (#rows).
  Eigen::VectorXd column(const std::string& name) const;
};

/// Writes `header` and `rows` (#rows x header.size()) as CSV with `precision` significant digits
/// (1..17; 17 reads back bit-exact), via a temporary file and a rename. NaN is written as `nan`.
void write_csv(const std::filesystem::path& path, const std::vector<std::string>& header,
               const Eigen::MatrixXd& rows, int precision = 10);

/// Reads a CSV written by write_csv or by hand: blank lines and lines starting with '#' are
/// skipped, cells are trimmed, `\r\n` line ends are accepted. Every cell after the header must be
/// a number (`nan` and `inf` included). Throws IoError when the file cannot be read and DataError
/// naming file, line and column for a malformed table.
CsvTable read_numeric_csv(const std::filesystem::path& path);

}  // namespace tt::io
