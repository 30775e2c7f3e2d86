// Runs build/thermotwin as a child process, as a user or a crash would: to the end, or killed.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/errors.hpp"
#include "io/child_process.hpp"

namespace tt::reliability_test {

namespace fs = std::filesystem;

inline const fs::path kThermotwin = fs::path(TT_BINARY_DIR) / "thermotwin";
inline const fs::path kCoarseCase = fs::path(TT_SOURCE_DIR) / "cases" / "sb1_coarse.toml";

/// A fresh scratch folder for one test, under the build tree.
inline fs::path scratch(const std::string& name) {
  const fs::path d = fs::path(TT_BINARY_DIR) / "reliability_scratch" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

/// Starts thermotwin with `args` (an argument vector: no shell); `env` entries ("K=V") are added
/// to (or override) the environment. stdout and stderr are appended to `log`.
inline pid_t start(const std::vector<std::string>& args, const std::vector<std::string>& env = {},
                   const fs::path& log = "/dev/null") {
  std::vector<std::string> argv{kThermotwin.string()};
  argv.insert(argv.end(), args.begin(), args.end());
  return io::start_program(argv, env, log);
}

/// Exit code of a child, or 128 + signal when a signal ended it.
inline int wait_for(pid_t pid) {
  return io::wait_program(pid);
}

inline int run(const std::vector<std::string>& args, const std::vector<std::string>& env = {},
               const fs::path& log = "/dev/null") {
  return wait_for(start(args, env, log));
}

/// Every regular file under `dir` (relative path -> bytes).
inline std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  if (!fs::exists(dir)) return files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::ifstream in(e.path(), std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    files[fs::relative(e.path(), dir).string()] = s.str();
  }
  return files;
}

inline std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A --dump file: the matrices it holds, as (rows, cols, values).
struct Dumped {
  std::int64_t rows = 0, cols = 0;
  std::vector<double> values;
};
inline std::vector<Dumped> read_dump(const fs::path& file) {
  const std::string bytes = read_text(file);
  std::vector<Dumped> out;
  std::size_t at = 0;
  while (at + 16 <= bytes.size()) {
    Dumped d;
    std::memcpy(&d.rows, bytes.data() + at, 8);
    std::memcpy(&d.cols, bytes.data() + at + 8, 8);
    at += 16;
    d.values.resize(static_cast<std::size_t>(d.rows * d.cols));
    if (at + d.values.size() * 8 > bytes.size())
      throw std::runtime_error(file.string() + ": truncated dump");
    std::memcpy(d.values.data(), bytes.data() + at, d.values.size() * 8);
    at += d.values.size() * 8;
    out.push_back(std::move(d));
  }
  return out;
}

/// The inputs that made a fuzz target fail, kept in fuzz/regressions/<reader>/, in name order.
inline std::vector<fs::path> fuzz_regressions(const std::string& reader) {
  const fs::path dir = fs::path(TT_SOURCE_DIR) / "fuzz" / "regressions" / reader;
  std::vector<fs::path> files;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

/// "" when `read` ends in success or a project error, else what escaped.
template <class Read>
std::string escaped(Read&& read) {
  try {
    read();
  } catch (const core::Error&) {
  } catch (const std::exception& e) {
    return std::string("std::exception: ") + e.what();
  } catch (...) {
    return "a non-standard exception";
  }
  return "";
}

}  // namespace tt::reliability_test
