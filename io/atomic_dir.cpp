#include "io/atomic_dir.hpp"

#include <fstream>
#include <system_error>

#include "core/errors.hpp"

namespace tt::io {

namespace fs = std::filesystem;

OutputDir::OutputDir(fs::path final_dir) : final_(std::move(final_dir)) {
  partial_ = final_;
  partial_ += ".partial";
  std::error_code ec;
  fs::remove_all(partial_, ec);
  fs::create_directories(partial_, ec);
  if (ec) throw core::IoError(partial_.string() + ": cannot create output directory: " + ec.message());
}

OutputDir::~OutputDir() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(partial_, ec);
  }
}

void OutputDir::commit() {
  std::error_code ec;
  const fs::path old = fs::path(final_.string() + ".old");
  fs::remove_all(old, ec);
  if (fs::exists(final_)) {
    fs::rename(final_, old, ec);
    if (ec) throw core::IoError(final_.string() + ": cannot move the previous result aside: " + ec.message());
  }
  fs::rename(partial_, final_, ec);
  if (ec) throw core::IoError(final_.string() + ": cannot publish the result: " + ec.message());
  fs::remove_all(old, ec);
  committed_ = true;
}

void write_file_atomically(const fs::path& path, const std::string& content) {
  fs::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << content;
    if (!out) throw core::IoError(tmp.string() + ": cannot write");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw core::IoError(path.string() + ": cannot rename from " + tmp.string() + ": " + ec.message());
}

}  // namespace tt::io
