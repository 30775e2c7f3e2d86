// Results appear whole or not at all: a run writes into DIR.partial/ and publishes it as DIR when
// complete; files are written to a temporary name and renamed.
//
// Killed at any moment, a run leaves at DIR either the previous complete result or none (when
// there was none), never a mixture. Publishing swaps DIR.partial and DIR in one renameat2
// (RENAME_EXCHANGE) and then removes the old result, now at DIR.partial. Where the file system
// cannot exchange, the previous result is first renamed to DIR.old; a kill between that rename and
// the next leaves DIR.old, which the next OutputDir for DIR renames back to DIR before it starts.
#pragma once

#include <filesystem>
#include <string>

namespace tt::io {

/// An output directory under construction. Files go to path(); commit() publishes it as the final
/// directory (replacing a previous complete result); destruction without commit() removes it.
class OutputDir {
 public:
  /// Restores a previous result left at DIR.old by a killed commit, then starts DIR.partial afresh.
  explicit OutputDir(std::filesystem::path final_dir);
  ~OutputDir();
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  const std::filesystem::path& path() const { return partial_; }
  const std::filesystem::path& final_path() const { return final_; }
  void commit();

 private:
  std::filesystem::path final_;
  std::filesystem::path partial_;
  bool committed_ = false;
};

/// Writes `content` to path via a temporary file and a rename.
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

}  // namespace tt::io
