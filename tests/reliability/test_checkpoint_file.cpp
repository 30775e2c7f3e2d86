// The checkpoint file: a state read back is the state written, bit for bit; a file for another
// case or mesh, a truncated or corrupted one is refused with a DataError that says so.
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "io/checkpoint.hpp"
#include "tests/reliability/process.hpp"

namespace tt::reliability_test {
namespace {

solvers::ThermalCheckpoint sample_state(int nodes, int cols) {
  solvers::ThermalCheckpoint s;
  s.steps = 17;
  s.time = 204.0;
  s.speed = 3000;
  s.temperature = Eigen::VectorXd::LinSpaced(nodes, 293.15, 300.0);
  s.temperature(1) = 293.15 + 1e-13;  // exact bits matter
  s.outputs = Eigen::MatrixXd::Random(nodes, cols).array() + 293.0;
  s.heat_in = 1234.5678901234567;
  s.lost = 0.1 + 0.2;
  return s;
}

io::CheckpointKey sample_key(int nodes) {
  io::CheckpointKey k;
  k.case_hash = 0x1234;
  k.mesh_hash = 0xabcd;
  k.nodes = nodes;
  k.tets = 99;
  k.order = 1;
  return k;
}

std::string data_error(const fs::path& file, const io::CheckpointKey& key) {
  try {
    io::read_checkpoint(file, key);
  } catch (const core::DataError& e) {
    return e.what();
  }
  return "";
}

TEST(CheckpointFile, ReadsBackBitForBit) {
  const fs::path file = scratch("checkpoint_roundtrip") / "run.checkpoint";
  const auto s = sample_state(50, 4);
  io::write_checkpoint(file, sample_key(50), s);
  const auto r = io::read_checkpoint(file, sample_key(50));
  EXPECT_EQ(r.steps, s.steps);
  EXPECT_EQ(r.time, s.time);
  EXPECT_EQ(r.speed, s.speed);
  EXPECT_EQ(r.heat_in, s.heat_in);
  EXPECT_EQ(r.lost, s.lost);
  EXPECT_TRUE(r.temperature == s.temperature);
  EXPECT_TRUE(r.outputs == s.outputs);
}

TEST(CheckpointFile, AnotherCaseOrMeshIsRefused) {
  const fs::path file = scratch("checkpoint_key") / "run.checkpoint";
  io::write_checkpoint(file, sample_key(50), sample_state(50, 4));
  auto other = sample_key(50);
  other.case_hash = 0x9999;
  EXPECT_NE(data_error(file, other).find("another case or mesh"), std::string::npos);
  other = sample_key(50);
  other.mesh_hash = 1;
  EXPECT_NE(data_error(file, other).find("another case or mesh"), std::string::npos);
}

TEST(CheckpointFile, TruncatedCorruptedOrForeignFilesAreRefused) {
  const fs::path dir = scratch("checkpoint_bad");
  const fs::path file = dir / "run.checkpoint";
  io::write_checkpoint(file, sample_key(50), sample_state(50, 4));
  const std::string bytes = read_text(file);
  std::ofstream(file, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_NE(data_error(file, sample_key(50)), "");
  std::string flipped = bytes;
  flipped[100] ^= 1;
  std::ofstream(file, std::ios::binary) << flipped;
  EXPECT_NE(data_error(file, sample_key(50)).find("checksum"), std::string::npos);
  std::ofstream(file, std::ios::binary) << "not a checkpoint at all";
  EXPECT_NE(data_error(file, sample_key(50)).find("TTCKPT01"), std::string::npos);
  EXPECT_THROW(io::read_checkpoint(dir / "absent.checkpoint", sample_key(50)), core::IoError);
}

TEST(CheckpointFile, PathSitsBesideTheOutputDirectory) {
  EXPECT_EQ(io::checkpoint_path("out/sb1"), fs::absolute("out/sb1.checkpoint"));
  EXPECT_EQ(io::checkpoint_path("out/sb1/"), fs::absolute("out/sb1.checkpoint"));
}

TEST(CheckpointFile, OneThatCannotBeSavedIsFoundBeforeTheRun) {
  const fs::path dir = scratch("ckpt_writable");
  EXPECT_NO_THROW(io::require_writable_checkpoint(dir / "new.checkpoint"));
  EXPECT_TRUE(fs::is_empty(dir)) << "the check left a file";

  std::ofstream(dir / "ro.checkpoint") << "x";
  fs::permissions(dir / "ro.checkpoint", fs::perms::owner_read);
  try {
    io::require_writable_checkpoint(dir / "ro.checkpoint");
    ADD_FAILURE() << "a read-only checkpoint was accepted";
  } catch (const core::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("read-only"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--checkpoint-every-s -1"), std::string::npos);
  }
  fs::create_directories(dir / "folder.checkpoint");
  EXPECT_THROW(io::require_writable_checkpoint(dir / "folder.checkpoint"), core::IoError);
  std::ofstream(dir / "file") << "x";
  EXPECT_THROW(io::require_writable_checkpoint(dir / "file" / "out.checkpoint"), core::IoError);
}

TEST(CheckpointFile, ASaveThatFailsLeavesNoTemporaryFile) {
  const fs::path dir = scratch("ckpt_save_fails");
  // The rename fails: a non-empty folder holds the checkpoint's name.
  fs::create_directories(dir / "out.checkpoint" / "x");
  EXPECT_THROW(io::write_checkpoint(dir / "out.checkpoint", sample_key(50), sample_state(50, 3)),
               core::IoError);
  EXPECT_FALSE(fs::exists(dir / "out.checkpoint.tmp"));
  // The write fails: the temporary name leads to a full device.
  fs::create_symlink("/dev/full", dir / "b.checkpoint.tmp");
  EXPECT_THROW(io::write_checkpoint(dir / "b.checkpoint", sample_key(50), sample_state(50, 3)),
               core::IoError);
  EXPECT_FALSE(fs::exists(fs::symlink_status(dir / "b.checkpoint.tmp")));
  EXPECT_FALSE(fs::exists(dir / "b.checkpoint"));
}

}  // namespace
}  // namespace tt::reliability_test
