// OutputDir publishes whole results: commit swaps in the new directory, an uncommitted one leaves
// nothing, and a previous result set aside as DIR.old by an interrupted commit is restored.
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
  fs::create_directories(dir / "res.partial");
  put(dir / "res.partial" / "a.txt", "new but never published");
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
