#include "io/atomic_dir.hpp"

#include <dirent.h>  // getdents64 (glibc >= 2.30)
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (glibc >= 2.28)
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>

#include "core/errors.hpp"

namespace tt::io {

namespace fs = std::filesystem;

namespace {

/// `p` without a trailing separator ("out/" -> "out").
fs::path without_trailing_slash(fs::path p) {
  while (!p.has_filename() && p.has_relative_path()) p = p.parent_path();
  return p;
}

/// Absolute, symbolic links resolved as far as the path exists, no trailing separator: the form
/// in which two names of one file compare equal.
fs::path resolved(const fs::path& p) {
  std::error_code ec;
  fs::path r = fs::weakly_canonical(fs::absolute(p), ec);
  if (ec) r = fs::absolute(p).lexically_normal();
  return without_trailing_slash(r);
}

/// True when `inner` is `outer` or lies below it (both resolved).
bool is_within(const fs::path& inner, const fs::path& outer) {
  const auto [o, i] = std::mismatch(outer.begin(), outer.end(), inner.begin(), inner.end());
  return o == outer.end();
}

/// What lies at an output path: how OutputDir may treat it.
enum class Found { nothing, empty_folder, result, partial, folder, symlink, other };

Found found_at(const fs::path& p) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(p, ec);
  if (ec || st.type() == fs::file_type::not_found) return Found::nothing;
  if (st.type() == fs::file_type::symlink) return Found::symlink;
  if (st.type() != fs::file_type::directory) return Found::other;
  if (fs::is_regular_file(fs::symlink_status(p / kResultStamp, ec))) return Found::result;
  if (fs::is_regular_file(fs::symlink_status(p / kPartialMarker, ec))) return Found::partial;
  if (fs::is_empty(p, ec) && !ec) return Found::empty_folder;
  return Found::folder;
}

std::string not_ours(const fs::path& p, Found f) {
  switch (f) {
    case Found::symlink:
      return p.string() + " is a symbolic link";
    case Found::other:
      return p.string() + " exists and is not a folder";
    default:
      return p.string() + " is a folder that thermotwin did not write (it holds no " +
             kResultStamp + ")";
  }
}

bool is_mark(const fs::path& name) {
  return name == kPartialMarker || name == kResultStamp;
}

/// Removes a folder of thermotwin's, its marker or stamp last: a removal cut short by a kill
/// leaves a folder that is still recognised as thermotwin's, and removed by the next command.
void remove_ours(const fs::path& dir) {
  std::error_code ec;
  if (fs::is_symlink(dir, ec) || !fs::is_directory(dir, ec)) return;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (!is_mark(e.path().filename())) fs::remove_all(e.path(), ec);
  fs::remove_all(dir, ec);
}

/// Throws unless DIR can be replaced: missing, an empty folder or a stamped result.
void require_replaceable(const fs::path& dir) {
  const Found f = found_at(dir);
  if (f == Found::nothing || f == Found::empty_folder || f == Found::result) return;
  throw core::IoError("output " + dir.string() + ": " + not_ours(dir, f) +
                      "; thermotwin replaces only its own earlier results and empty folders. "
                      "Hint: choose another --out, or move " +
                      dir.filename().string() + " away first");
}

/// Throws when an output path is, contains or lies inside one of the inputs.
void require_apart(const std::vector<fs::path>& outputs, const fs::path& given,
                   const std::vector<fs::path>& inputs) {
  for (const auto& input : inputs) {
    if (input.empty()) continue;
    const fs::path in = resolved(input);
    for (const auto& output : outputs) {
      const fs::path out = resolved(output);
      const char* how = out == in            ? "is"
                        : is_within(in, out) ? "contains"
                        : is_within(out, in) ? "lies inside"
                                             : nullptr;
      if (!how) continue;
      throw core::IoError("output " + given.string() + ": " + output.string() + " " + how +
                          " the input " + input.string() +
                          ", which writing the result would replace or delete. Hint: give an "
                          "--out outside every input of the command");
    }
  }
}

/// The pid written into a lock file by the process that holds it, or "" when unknown.
std::string holder_of(int fd) {
  char buf[32] = {};
  const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
  std::string s(buf, n > 0 ? static_cast<size_t>(n) : 0);
  s.erase(std::remove(s.begin(), s.end(), '\n'), s.end());
  return s;
}

/// An open descriptor of `lock_file` holding its flock. A writer that ends removes the file while
/// it holds the lock: a lock taken on a file removed meanwhile is dropped and taken again.
int locked_file(const fs::path& lock_file, const fs::path& dir) {
  for (int attempt = 0; attempt < 16; ++attempt) {
    const int fd = ::open(lock_file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd < 0)
      throw core::IoError("output " + dir.string() + ": cannot create the lock file " +
                          lock_file.string() + ": " + std::strerror(errno) +
                          ". Hint: --out must lie in a folder you can write to");
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      const std::string pid = holder_of(fd);
      ::close(fd);
      if (err == EWOULDBLOCK)
        throw core::IoError("output " + dir.string() + ": another thermotwin command" +
                            (pid.empty() ? "" : " (pid " + pid + ")") +
                            " is writing this output and holds " + lock_file.string() +
                            "; two commands with one --out would mix their files. Hint: wait "
                            "for it to end, or choose another --out");
      throw core::IoError("output " + dir.string() + ": cannot lock " + lock_file.string() + ": " +
                          std::strerror(err));
    }
    struct stat by_fd {
    }, by_path{};
    if (::fstat(fd, &by_fd) == 0 && ::stat(lock_file.c_str(), &by_path) == 0 &&
        by_fd.st_dev == by_path.st_dev && by_fd.st_ino == by_path.st_ino) {
      // The pid only makes the message to a refused second writer more helpful.
      const std::string pid = std::to_string(::getpid()) + "\n";
      const bool noted = ::ftruncate(fd, 0) == 0 && ::pwrite(fd, pid.data(), pid.size(), 0) > 0;
      (void)noted;
      return fd;
    }
    ::close(fd);
  }
  throw core::IoError("output " + dir.string() + ": cannot lock " + lock_file.string() +
                      ": it is removed and created again by other processes");
}

// ---- Clean-up on SIGINT/SIGTERM/SIGHUP: only async-signal-safe calls below. ----

/// The DIR.partial, DIR.lock and DIR.checkpoint.tmp (a checkpoint being saved) of a live
/// OutputDir, as C strings a signal handler can read.
struct SignalSlot {
  volatile sig_atomic_t used = 0;
  char partial[PATH_MAX] = {};
  char lock[PATH_MAX] = {};
  char checkpoint_tmp[PATH_MAX] = {};
};
SignalSlot g_slots[4];

bool is_mark(const char* name) {
  return std::strcmp(name, kPartialMarker) == 0 || std::strcmp(name, kResultStamp) == 0;
}

/// Removes `name` (relative to `parent_fd`) and everything below it, the marker or stamp of the
/// top folder last (as remove_ours); gives up below 16 levels.
void remove_tree(int parent_fd, const char* name, int depth) {
  if (::unlinkat(parent_fd, name, 0) == 0) return;
  const int fd = ::openat(parent_fd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return;
  if (depth < 16) {
    alignas(struct dirent64) char buf[2048];
    for (int pass = 0; pass < 64; ++pass) {  // entries are re-read: removal shifts the listing
      ::lseek(fd, 0, SEEK_SET);
      const ssize_t n = ::getdents64(fd, buf, sizeof buf);
      if (n <= 0) break;
      bool any = false;
      for (ssize_t at = 0; at < n;) {
        const auto* d = reinterpret_cast<const struct dirent64*>(buf + at);
        at += d->d_reclen;
        if (std::strcmp(d->d_name, ".") == 0 || std::strcmp(d->d_name, "..") == 0) continue;
        if (depth == 0 && is_mark(d->d_name)) continue;
        any = true;
        remove_tree(fd, d->d_name, depth + 1);
      }
      if (!any) break;
    }
  }
  if (depth == 0) {
    ::unlinkat(fd, kPartialMarker, 0);
    ::unlinkat(fd, kResultStamp, 0);
  }
  ::close(fd);
  ::unlinkat(parent_fd, name, AT_REMOVEDIR);
}

extern "C" void remove_outputs_and_end(int sig) {
  for (auto& s : g_slots) {
    if (!s.used) continue;
    remove_tree(AT_FDCWD, s.partial, 0);
    ::unlink(s.checkpoint_tmp);
    ::unlink(s.lock);
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);  // delivered when the handler returns: the process ends as the signal would
}

int register_for_signals(const fs::path& final_dir) {
  const std::string p = sibling_path(final_dir, ".partial").string();
  const std::string l = sibling_path(final_dir, ".lock").string();
  const std::string c = sibling_path(final_dir, ".checkpoint.tmp").string();
  if (c.size() >= PATH_MAX) return -1;
  for (int k = 0; k < static_cast<int>(std::size(g_slots)); ++k) {
    if (g_slots[k].used) continue;
    std::memcpy(g_slots[k].partial, p.c_str(), p.size() + 1);
    std::memcpy(g_slots[k].lock, l.c_str(), l.size() + 1);
    std::memcpy(g_slots[k].checkpoint_tmp, c.c_str(), c.size() + 1);
    g_slots[k].used = 1;
    return k;
  }
  return -1;  // more live outputs than slots: a leftover is removed by the next run
}

}  // namespace

fs::path output_path(const fs::path& given) {
  const fs::path p = without_trailing_slash(fs::absolute(given).lexically_normal());
  if (!p.has_filename() || p.filename() == "." || p.filename() == "..")
    throw core::IoError("output " + given.string() +
                        ": not a folder name. Hint: --out names the folder to write, e.g. "
                        "--out results/run1");
  return p;
}

fs::path sibling_path(const fs::path& dir, const char* suffix) {
  fs::path s = dir;
  s += suffix;
  return s;
}

OutputDir::OutputDir(const fs::path& final_dir, const std::vector<fs::path>& inputs)
    : final_(output_path(final_dir)),
      partial_(sibling_path(final_, ".partial")),
      old_(sibling_path(final_, ".old")),
      lock_(sibling_path(final_, ".lock")) {
  for (const char* kept : {".partial", ".old", ".lock", ".checkpoint"})
    if (final_.extension() == kept)
      throw core::IoError("output " + final_dir.string() + ": a name ending in " + kept +
                          " is kept for what thermotwin puts beside an output (DIR.partial, "
                          "DIR.old, DIR.lock, DIR.checkpoint). Hint: choose another name");
  require_apart({final_, partial_, old_, lock_}, final_dir, inputs);
  std::error_code ec;
  fs::create_directories(final_.parent_path(), ec);
  if (ec)
    throw core::IoError("output " + final_.string() + ": cannot create the folder " +
                        final_.parent_path().string() + ": " + ec.message());
  lock_fd_ = locked_file(lock_, final_);
  try {
    // A result set aside by a killed commit goes back to DIR; another DIR.old is the user's.
    if (found_at(final_) == Found::nothing && found_at(old_) == Found::result) {
      fs::rename(old_, final_, ec);
      if (ec)
        throw core::IoError(old_.string() +
                            ": a previous result left by an interrupted run cannot be restored "
                            "to " +
                            final_.string() + ": " + ec.message() + "; rename it by hand");
    }
    require_replaceable(final_);
    // Under the lock, a DIR.partial of thermotwin is a leftover of a killed command.
    const Found left = found_at(partial_);
    if (left == Found::partial || left == Found::result || left == Found::empty_folder)
      remove_ours(partial_);
    else if (left != Found::nothing)
      throw core::IoError("output " + final_.string() + ": " + not_ours(partial_, left) +
                          ", and thermotwin writes its result there first. Hint: move " +
                          partial_.filename().string() + " away, or choose another --out");
    // From here DIR.partial is ours: a signal removes it, even before the marker is written.
    signal_slot_ = register_for_signals(final_);
    fs::create_directory(partial_, ec);
    if (ec)
      throw core::IoError(partial_.string() + ": cannot create the output folder: " + ec.message());
    std::ofstream(partial_ / kPartialMarker) << "thermotwin is writing this folder; it is "
                                                "complete once this file is named "
                                             << kResultStamp << "\n";
    if (!fs::is_regular_file(partial_ / kPartialMarker))
      throw core::IoError(partial_.string() + ": cannot write into the output folder");
  } catch (...) {
    if (found_at(partial_) == Found::partial) remove_ours(partial_);
    release();
    throw;
  }
}

void OutputDir::release() {
  if (signal_slot_ >= 0) g_slots[signal_slot_].used = 0;
  signal_slot_ = -1;
  if (lock_fd_ >= 0) {
    ::unlink(lock_.c_str());  // while still locked: see locked_file
    ::close(lock_fd_);
  }
  lock_fd_ = -1;
}

OutputDir::~OutputDir() {
  if (!committed_) remove_ours(partial_);
  release();
}

void OutputDir::commit() {
  // Under the lock only a user puts something at DIR; it is not replaced without the stamp.
  require_replaceable(final_);
  std::error_code ec;
  fs::rename(partial_ / kPartialMarker, partial_ / kResultStamp, ec);
  if (ec) throw core::IoError(partial_.string() + ": cannot stamp the result: " + ec.message());
  if (found_at(final_) != Found::nothing) {
    // One atomic swap: DIR is the previous result before, the new one after, never absent.
    if (::renameat2(AT_FDCWD, partial_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) == 0) {
      committed_ = true;
      remove_ours(partial_);  // the previous result; a leftover is removed by the next run
      return;
    }
    if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP)
      throw core::IoError(final_.string() + ": cannot exchange with " + partial_.string() + ": " +
                          std::strerror(errno));
    // No exchange on this file system: set the previous result aside where the next run finds it.
    const Found old = found_at(old_);
    if (old == Found::result)
      remove_ours(old_);
    else if (old != Found::nothing)
      throw core::IoError("output " + final_.string() + ": " + not_ours(old_, old) +
                          ", and this file system needs it to set the previous result aside. "
                          "Hint: move " +
                          old_.filename().string() + " away and run again");
    fs::rename(final_, old_, ec);
    if (ec)
      throw core::IoError(final_.string() +
                          ": cannot move the previous result aside: " + ec.message());
    fs::rename(partial_, final_, ec);
    if (ec) throw core::IoError(final_.string() + ": cannot publish the result: " + ec.message());
    committed_ = true;
    remove_ours(old_);
    return;
  }
  fs::rename(partial_, final_, ec);
  if (ec) throw core::IoError(final_.string() + ": cannot publish the result: " + ec.message());
  committed_ = true;
}

void clean_up_outputs_on_signals() {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction current {};
    if (::sigaction(sig, nullptr, &current) != 0 || current.sa_handler != SIG_DFL) continue;
    struct sigaction on {};
    on.sa_handler = remove_outputs_and_end;
    sigemptyset(&on.sa_mask);
    for (const int other : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&on.sa_mask, other);
    ::sigaction(sig, &on, nullptr);
  }
}

void write_file_atomically(const fs::path& path, const std::string& content) {
  const fs::path tmp = sibling_path(path, ".tmp");
  std::error_code ec;
  {
    std::ofstream out(tmp, std::ios::binary);
    out << content;
    out.close();
    if (!out) {
      fs::remove(tmp, ec);
      throw core::IoError(tmp.string() + ": cannot write");
    }
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    const std::string why = ec.message();
    fs::remove(tmp, ec);
    throw core::IoError(path.string() + ": cannot rename from " + tmp.string() + ": " + why);
  }
}

}  // namespace tt::io
