// Results appear whole or not at all, only where the user asked for them, one writer at a time.
//
// A command writes into DIR.partial/ and publishes it as DIR when complete. DIR.partial holds
// the marker .thermotwin-partial from its creation; commit() renames it to the stamp
// .thermotwin-result (the last change to the result) and swaps DIR.partial and DIR in one
// renameat2 (RENAME_EXCHANGE), then removes the old result, now at DIR.partial. Where the file
// system cannot exchange, the previous result is first renamed to DIR.old; a kill between that
// rename and the next leaves DIR.old, which the next OutputDir for DIR renames back to DIR.
//
// What an OutputDir replaces and what it refuses (core::IoError, at construction, so before the
// command's work; the message says why and how to proceed):
// - DIR may be missing, an empty folder or a folder holding the stamp (an earlier result of
//   thermotwin). A file, a symbolic link or a folder without the stamp is refused.
// - DIR, DIR.partial and DIR.old may not be, contain or lie inside one of the command's inputs.
// - A leftover DIR.partial is removed only when it holds the marker, the stamp or nothing; DIR.old
//   is restored or removed only when it holds the stamp. Anything else is left alone (refused).
// - DIR.lock is locked (flock, advisory) from construction to destruction: a second command with
//   the same DIR is refused at once, naming the process that writes it. The file is removed when
//   the lock is released.
// - DIR may not end in .partial, .old, .lock or .checkpoint (the names beside an output).
// "DIR" is the absolute path without a trailing slash: `--out out/` is `--out out`.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace tt::io {

/// In a published result: written last, so a folder holding it is a whole result of thermotwin.
inline constexpr const char* kResultStamp = ".thermotwin-result";
/// In DIR.partial while it is written.
inline constexpr const char* kPartialMarker = ".thermotwin-partial";

/// The output folder `given` names, as OutputDir publishes it: absolute, lexically normal, no
/// trailing slash. Throws IoError for a path with no name (the root folder).
std::filesystem::path output_path(const std::filesystem::path& given);

/// `dir` with `suffix` appended to its name: sibling_path("/a/out", ".lock") = "/a/out.lock".
std::filesystem::path sibling_path(const std::filesystem::path& dir, const char* suffix);

/// An output directory under construction. Files go to path(); commit() publishes it as the final
/// directory (replacing a previous result); destruction without commit() removes it.
class OutputDir {
 public:
  /// Takes DIR.lock, refuses what the rules above refuse, restores a result left at DIR.old by a
  /// killed commit and starts DIR.partial afresh. `inputs`: every file and folder the command
  /// reads (case file, files the case names, measured runs, run folders, checkpoint).
  explicit OutputDir(const std::filesystem::path& final_dir,
                     const std::vector<std::filesystem::path>& inputs = {});
  ~OutputDir();
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  const std::filesystem::path& path() const { return partial_; }
  const std::filesystem::path& final_path() const { return final_; }
  /// Stamps DIR.partial and publishes it as DIR. Throws IoError when something that is not a
  /// result of thermotwin appeared at DIR (or DIR.old) meanwhile; DIR is then left as it was.
  void commit();

 private:
  void release();

  std::filesystem::path final_, partial_, old_, lock_;
  int lock_fd_ = -1;
  int signal_slot_ = -1;
  bool committed_ = false;
};

/// For drivers, once at start: on SIGINT, SIGTERM or SIGHUP, remove the DIR.partial, DIR.lock and
/// DIR.checkpoint.tmp of every live OutputDir, then end as the signal would have (exit status
/// 128 + signal). DIR keeps the previous result; a run's DIR.checkpoint stays, for --resume.
/// Signals the process ignores stay ignored.
void clean_up_outputs_on_signals();

/// Writes `content` to path via path.tmp and a rename; when that fails, no path.tmp is left.
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

}  // namespace tt::io
