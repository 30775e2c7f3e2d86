// OutputDir publishes whole results: commit swaps in the new directory, an uncommitted one leaves
// nothing, and a previous result set aside as DIR.old by an interrupted commit is restored. It
// replaces only its own results and empty folders, never an input, and one writer at a time.
#include <gtest/gtest.h>

#include <fstream>

#include "io/atomic_dir.hpp"
#include "tests/reliability/process.hpp"

namespace tt::reliability_test {
namespace {

void put(const fs::path& file, const std::string& text) {
  std::ofstream(file) << text;
}

TEST(OutputDir, CommitReplacesThePreviousResultWhole) {
  const fs::path dir = scratch("outdir_replace");
  const fs::path out = dir / "res";
  {
    io::OutputDir o(out);
    put(o.path() / "a.txt", "first");
    put(o.path() / "only_first.txt", "x");
    o.commit();
  }
  {
    io::OutputDir o(out);
    EXPECT_EQ(read_text(out / "a.txt"), "first");  // untouched while the new one is written
    put(o.path() / "a.txt", "second");
    o.commit();
  }
  EXPECT_EQ(read_text(out / "a.txt"), "second");
  EXPECT_FALSE(fs::exists(out / "only_first.txt"));
  EXPECT_FALSE(fs::exists(dir / "res.partial"));
  EXPECT_FALSE(fs::exists(dir / "res.old"));
}

TEST(OutputDir, WithoutCommitNothingIsPublished) {
  const fs::path dir = scratch("outdir_abort");
  const fs::path out = dir / "res";
  {
    io::OutputDir o(out);
    put(o.path() / "a.txt", "half");
  }
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(dir / "res.partial"));
}

TEST(OutputDir, PreviousResultSetAsideByAKilledCommitIsRestored) {
  const fs::path dir = scratch("outdir_old");
  // What a commit killed between its two renames leaves on a file system without exchange.
  fs::create_directories(dir / "res.old");
  put(dir / "res.old" / "a.txt", "previous");
  put(dir / "res.old" / io::kResultStamp, "");
  fs::create_directories(dir / "res.partial");
  put(dir / "res.partial" / "a.txt", "new but never published");
  put(dir / "res.partial" / io::kResultStamp, "");
  {
    io::OutputDir o(dir / "res");
    EXPECT_EQ(read_text(dir / "res" / "a.txt"), "previous");
    EXPECT_FALSE(fs::exists(o.path() / "a.txt"));  // the stale partial is not reused
  }
  EXPECT_EQ(read_text(dir / "res" / "a.txt"), "previous");
}

TEST(OutputDir, WriteFileAtomicallyLeavesNoTemporary) {
  const fs::path dir = scratch("outdir_file");
  io::write_file_atomically(dir / "f.txt", "content");
  EXPECT_EQ(read_text(dir / "f.txt"), "content");
  EXPECT_FALSE(fs::exists(dir / "f.txt.tmp"));
}

}  // namespace
}  // namespace tt::reliability_test

namespace tt::reliability_test {
namespace {

/// The IoError message of `make`, or "" when it did not throw one.
template <class Make>
std::string refusal(Make&& make) {
  try {
    make();
  } catch (const core::IoError& e) {
    return e.what();
  }
  return "";
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(OutputDir, AResultIsStampedAndOnlyStampedOrEmptyFoldersAreReplaced) {
  const fs::path dir = scratch("outdir_stamp");
  {
    io::OutputDir o(dir / "res");
    EXPECT_TRUE(fs::exists(o.path() / io::kPartialMarker));
    put(o.path() / "a.txt", "x");
    o.commit();
  }
  EXPECT_TRUE(fs::exists(dir / "res" / io::kResultStamp));
  EXPECT_FALSE(fs::exists(dir / "res" / io::kPartialMarker));
  EXPECT_NO_THROW(io::OutputDir(dir / "res").commit());  // its own result

  fs::create_directories(dir / "empty");
  EXPECT_NO_THROW(io::OutputDir(dir / "empty").commit());
  EXPECT_TRUE(fs::exists(dir / "empty" / io::kResultStamp));

  put(dir / "file", "precious");
  std::string msg = refusal([&] { io::OutputDir o(dir / "file"); });
  EXPECT_TRUE(has(msg, "not a folder")) << msg;
  EXPECT_TRUE(has(msg, "Hint")) << msg;
  EXPECT_EQ(read_text(dir / "file"), "precious");

  fs::create_directories(dir / "mine");
  put(dir / "mine" / "notes.txt", "keep");
  msg = refusal([&] { io::OutputDir o(dir / "mine"); });
  EXPECT_TRUE(has(msg, io::kResultStamp)) << msg;
  EXPECT_EQ(read_text(dir / "mine" / "notes.txt"), "keep");

  fs::create_directory_symlink(dir / "res", dir / "link");
  msg = refusal([&] { io::OutputDir o(dir / "link"); });
  EXPECT_TRUE(has(msg, "symbolic link")) << msg;
  for (const char* left :
       {"file.partial", "file.lock", "mine.partial", "mine.lock", "link.partial"})
    EXPECT_FALSE(fs::exists(dir / left)) << left;
}

TEST(OutputDir, SomethingPutAtDirDuringTheWorkIsNotReplaced) {
  const fs::path dir = scratch("outdir_late");
  io::OutputDir o(dir / "res");
  put(dir / "res", "appeared meanwhile");
  EXPECT_THROW(o.commit(), core::IoError);
  EXPECT_EQ(read_text(dir / "res"), "appeared meanwhile");
}

TEST(OutputDir, AnInputIsNeverInsideOrAroundTheOutput) {
  const fs::path dir = scratch("outdir_inputs");
  fs::create_directories(dir / "cases");
  put(dir / "cases" / "case.toml", "case");
  fs::create_directories(dir / "run");
  put(dir / "run" / "data.csv", "data");
  const auto refused = [&](const fs::path& out, const fs::path& input) {
    return refusal([&] { io::OutputDir o(out, {input}); });
  };
  EXPECT_TRUE(has(refused(dir / "run", dir / "run"), "is the input"));
  EXPECT_TRUE(has(refused(dir / "run/", dir / "run" / "." / ""), "is the input"));
  EXPECT_TRUE(has(refused(dir / "cases", dir / "cases" / "case.toml"), "contains the input"));
  EXPECT_TRUE(has(refused(dir / "run" / "fit", dir / "run"), "lies inside the input"));
  EXPECT_TRUE(has(refused(dir / "x", dir / "x.partial"), "is the input"));
  EXPECT_EQ(read_text(dir / "cases" / "case.toml"), "case");
  EXPECT_EQ(read_text(dir / "run" / "data.csv"), "data");
  EXPECT_FALSE(fs::exists(dir / "run" / "fit"));
  EXPECT_FALSE(fs::exists(dir / "run" / "fit.partial"));
  // A sibling whose name only starts like the input's is not inside it.
  EXPECT_NO_THROW(io::OutputDir(dir / "run2", {dir / "run"}).commit());
}

TEST(OutputDir, AUsersOldAndPartialFoldersAreLeftAlone) {
  const fs::path dir = scratch("outdir_users_old");
  fs::create_directories(dir / "res.old");
  put(dir / "res.old" / "notes.txt", "mine");
  {
    io::OutputDir o(dir / "res");
    put(o.path() / "a.txt", "new");
    o.commit();
  }
  EXPECT_EQ(read_text(dir / "res" / "a.txt"), "new");
  EXPECT_EQ(read_text(dir / "res.old" / "notes.txt"), "mine");
  EXPECT_FALSE(fs::exists(dir / "res" / "notes.txt"));

  fs::create_directories(dir / "other.partial");
  put(dir / "other.partial" / "notes.txt", "mine too");
  const std::string msg = refusal([&] { io::OutputDir o(dir / "other"); });
  EXPECT_TRUE(has(msg, "other.partial")) << msg;
  EXPECT_EQ(read_text(dir / "other.partial" / "notes.txt"), "mine too");
}

TEST(OutputDir, TrailingSlashNamesTheSameFolder) {
  const fs::path dir = scratch("outdir_slash");
  {
    io::OutputDir o(dir / "res/");
    EXPECT_EQ(o.final_path(), dir / "res");
    EXPECT_EQ(o.path(), dir / "res.partial");
    put(o.path() / "a.txt", "x");
    o.commit();
  }
  EXPECT_EQ(read_text(dir / "res" / "a.txt"), "x");
  EXPECT_FALSE(fs::exists(dir / "res" / ".partial"));
  EXPECT_THROW(io::output_path("/"), core::IoError);
  EXPECT_THROW(io::OutputDir(dir / "res.partial"), core::IoError);  // the names beside an output
  EXPECT_THROW(io::OutputDir(dir / "res.old/"), core::IoError);
}

TEST(OutputDir, ASecondWriterIsRefusedAtOnceAndTheLockGoesWithTheFirst) {
  const fs::path dir = scratch("outdir_lock");
  {
    io::OutputDir first(dir / "res");
    EXPECT_TRUE(fs::exists(dir / "res.lock"));
    const std::string msg = refusal([&] { io::OutputDir second(dir / "res/"); });
    EXPECT_TRUE(has(msg, "another thermotwin command (pid " + std::to_string(getpid()) + ")"))
        << msg;
    EXPECT_TRUE(fs::exists(first.path() / io::kPartialMarker)) << "the refused writer touched it";
    first.commit();
  }
  EXPECT_FALSE(fs::exists(dir / "res.lock"));
  EXPECT_NO_THROW(io::OutputDir(dir / "res").commit());
}

TEST(OutputDir, WriteFileAtomicallyLeavesNoTemporaryWhenItFails) {
  const fs::path dir = scratch("outdir_file_fails");
  fs::create_directories(dir / "f.txt" / "x");  // the rename cannot replace a non-empty folder
  EXPECT_THROW(io::write_file_atomically(dir / "f.txt", "content"), core::IoError);
  EXPECT_FALSE(fs::exists(dir / "f.txt.tmp"));
}

}  // namespace
}  // namespace tt::reliability_test
