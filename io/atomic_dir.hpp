// Results appear whole or not at all: a run writes into DIR.partial/ and renames it to DIR when
// complete; files are written to a temporary name and renamed.
#pragma once

#include <filesystem>
#include <string>

namespace tt::io {

/// An output directory under construction. Files go to path(); commit() publishes it as the final
/// directory (replacing a previous complete result); destruction without commit() removes it.
class OutputDir {
 public:
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
