// Checks a command's output folder against its documented schemas (docs/schemas/) with
// scripts/validate_output.py, the checker users run too.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "io/child_process.hpp"

namespace tt::test {

/// Success when every JSON file that `command` wrote into `dir` matches its schema; otherwise the
/// checker's lines (file, JSON path, message).
inline ::testing::AssertionResult matches_output_schemas(const std::string& command,
                                                         const std::filesystem::path& dir) {
  const std::filesystem::path source(TT_SOURCE_DIR);
  const std::filesystem::path log = dir.parent_path() / (dir.filename().string() + ".schema.log");
  std::filesystem::remove(log);
  const int status =
      io::run_program({"/usr/bin/python3", (source / "scripts" / "validate_output.py").string(),
                       command, dir.string()},
                      {}, log);
  if (status == 0) return ::testing::AssertionSuccess();
  std::ostringstream text;
  text << std::ifstream(log).rdbuf();
  return ::testing::AssertionFailure() << command << " output " << dir << " against docs/schemas/"
                                       << " (exit " << status << "):\n"
                                       << text.str();
}

}  // namespace tt::test
