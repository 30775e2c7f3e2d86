// Rows of a CSV file with a header line, as maps from column name to cell text (a short row's
// missing cells empty): for tests that compare what a command wrote column by column.
#pragma once

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace tt::test {

inline std::vector<std::map<std::string, std::string>> csv_rows(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream h(line);
  for (std::string c; std::getline(h, c, ',');) header.push_back(c);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::map<std::string, std::string> row;
    std::stringstream s(line);
    std::string cell;
    for (std::size_t c = 0; c < header.size(); ++c) {
      if (!std::getline(s, cell, ',')) cell.clear();
      row[header[c]] = cell;
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace tt::test
