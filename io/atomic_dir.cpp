#include "io/atomic_dir.hpp"

#include <fcntl.h>
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (glibc >= 2.28)

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include "core/errors.hpp"

namespace tt::io {

namespace fs = std::filesystem;

namespace {

fs::path with_suffix(const fs::path& p, const char* suffix) {
  fs::path s = p;
  s += suffix;
  return s;
}

}  // namespace

OutputDir::OutputDir(fs::path final_dir) : final_(std::move(final_dir)) {
  partial_ = with_suffix(final_, ".partial");
  std::error_code ec;
  const fs::path old = with_suffix(final_, ".old");
  if (!fs::exists(final_, ec) && fs::is_directory(old, ec)) {
    fs::rename(old, final_, ec);
    if (ec)
      throw core::IoError(old.string() +
                          ": a previous result left by an interrupted run cannot be restored to " +
                          final_.string() + ": " + ec.message() + "; rename it by hand");
  }
  fs::remove_all(partial_, ec);
  fs::create_directories(partial_, ec);
  if (ec)
    throw core::IoError(partial_.string() + ": cannot create output directory: " + ec.message());
}

OutputDir::~OutputDir() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(partial_, ec);
  }
}

void OutputDir::commit() {
  std::error_code ec;
  if (fs::exists(final_, ec)) {
    // One atomic swap: DIR is the previous result before, the new one after, never absent.
    if (::renameat2(AT_FDCWD, partial_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) == 0) {
      committed_ = true;
      fs::remove_all(partial_, ec);  // the previous result; a leftover is removed by the next run
      return;
    }
    if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP)
      throw core::IoError(final_.string() + ": cannot exchange with " + partial_.string() + ": " +
                          std::strerror(errno));
    // No exchange on this file system: set the previous result aside where the next run finds it.
    const fs::path old = with_suffix(final_, ".old");
    fs::remove_all(old, ec);
    fs::rename(final_, old, ec);
    if (ec)
      throw core::IoError(final_.string() +
                          ": cannot move the previous result aside: " + ec.message());
    fs::rename(partial_, final_, ec);
    if (ec) throw core::IoError(final_.string() + ": cannot publish the result: " + ec.message());
    committed_ = true;
    fs::remove_all(old, ec);
    return;
  }
  fs::rename(partial_, final_, ec);
  if (ec) throw core::IoError(final_.string() + ": cannot publish the result: " + ec.message());
  committed_ = true;
}

void write_file_atomically(const fs::path& path, const std::string& content) {
  const fs::path tmp = with_suffix(path, ".tmp");
  {
    std::ofstream out(tmp, std::ios::binary);
    out << content;
    if (!out) throw core::IoError(tmp.string() + ": cannot write");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec)
    throw core::IoError(path.string() + ": cannot rename from " + tmp.string() + ": " +
                        ec.message());
}

}  // namespace tt::io
