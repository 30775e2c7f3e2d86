// A long run killed after a checkpoint resumes with --resume and ends with the numbers of a run
// that was never interrupted (asked: 1e-12 relative; the loop restarts from the exact state, so
// they agree bit for bit). The checkpoint is removed on success; one written for another case is
// refused. Both time schemes, on the coarse SB-1 case (600 steps of 12 s).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tests/reliability/process.hpp"

namespace tt::reliability_test {
namespace {

fs::path with_suffix(const fs::path& p, const char* s) {
  fs::path q = p;
  q += s;
  return q;
}

/// The coarse case with `from` replaced by `to`, written into `dir`.
fs::path case_variant(const fs::path& dir, const std::string& from, const std::string& to) {
  std::string text = read_text(kCoarseCase);
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("'" + from + "' not in the coarse case");
  text.replace(at, from.size(), to);
  const fs::path file = dir / "case.toml";
  std::ofstream(file) << text;
  return file;
}

double max_relative_difference(const Dumped& a, const Dumped& b) {
  double worst = 0;
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    const double scale = std::max(std::abs(a.values[i]), 1e-300);
    worst = std::max(worst, std::abs(a.values[i] - b.values[i]) / scale);
  }
  return worst;
}

void expect_resume_matches(const fs::path& dir, const fs::path& case_file, int stop_after) {
  const fs::path whole = dir / "whole", cut = dir / "cut";
  ASSERT_EQ(run({"run", case_file.string(), "--out", whole.string(), "--quiet", "--dump",
                 (dir / "whole.bin").string()}),
            0);
  // Interrupted: the hidden flag saves a checkpoint after `stop_after` steps and exits as if
  // killed.
  ASSERT_EQ(run({"run", case_file.string(), "--out", cut.string(), "--quiet", "--stop-after-steps",
                 std::to_string(stop_after)}),
            3);
  EXPECT_FALSE(fs::exists(cut));
  ASSERT_TRUE(fs::exists(with_suffix(cut, ".checkpoint")));
  const fs::path log = dir / "resume.log";
  ASSERT_EQ(run({"run", case_file.string(), "--out", cut.string(), "--quiet", "--resume", "--dump",
                 (dir / "cut.bin").string()},
                {}, log),
            0);
  EXPECT_NE(read_text(log).find("resuming at t = " + std::to_string(12 * stop_after)),
            std::string::npos)
      << read_text(log);
  EXPECT_FALSE(fs::exists(with_suffix(cut, ".checkpoint"))) << "checkpoint left after success";

  const auto a = read_dump(dir / "whole.bin"), b = read_dump(dir / "cut.bin");
  ASSERT_EQ(a.size(), 2u);  // temperatures, displacements
  ASSERT_EQ(b.size(), a.size());
  for (std::size_t m = 0; m < a.size(); ++m) {
    ASSERT_EQ(a[m].rows, b[m].rows);
    ASSERT_EQ(a[m].cols, b[m].cols);
    EXPECT_LE(max_relative_difference(a[m], b[m]), 1e-12) << "matrix " << m;
  }
  EXPECT_EQ(read_text(whole / "temperatures.csv"), read_text(cut / "temperatures.csv"));
  EXPECT_EQ(read_text(whole / "thermal_error.csv"), read_text(cut / "thermal_error.csv"));
}

TEST(Resume, BackwardEulerEndsAsIfNeverInterrupted) {
  const fs::path dir = scratch("resume_be");
  // Step 230 is inside the third running segment, after two speed changes.
  expect_resume_matches(dir, kCoarseCase, 230);
}

TEST(Resume, CrankNicolsonAtASpeedChangeEndsAsIfNeverInterrupted) {
  const fs::path dir = scratch("resume_cn");
  const fs::path c =
      case_variant(dir, "scheme = \"backward_euler\"", "scheme = \"crank_nicolson\"");
  // Step 50 ends at t = 600 s, where the spindle stops: the resumed step must restart CN.
  expect_resume_matches(dir, c, 50);
}

TEST(Resume, CheckpointOfAnotherCaseIsRefused) {
  const fs::path dir = scratch("resume_other");
  const fs::path out = dir / "run";
  ASSERT_EQ(run({"run", kCoarseCase.string(), "--out", out.string(), "--quiet",
                 "--stop-after-steps", "20"}),
            3);
  const fs::path other = case_variant(dir, "h_W_m2K = 8.0", "h_W_m2K = 9.0");
  const fs::path log = dir / "other.log";
  EXPECT_EQ(run({"run", other.string(), "--out", out.string(), "--quiet", "--resume"}, {}, log), 1);
  EXPECT_NE(read_text(log).find("another case or mesh"), std::string::npos) << read_text(log);
  EXPECT_FALSE(fs::exists(out));
}

TEST(Resume, CorruptedCheckpointIsRefused) {
  const fs::path dir = scratch("resume_corrupt");
  const fs::path out = dir / "run";
  ASSERT_EQ(run({"run", kCoarseCase.string(), "--out", out.string(), "--quiet",
                 "--stop-after-steps", "20"}),
            3);
  const fs::path cp = with_suffix(out, ".checkpoint");
  std::string bytes = read_text(cp);
  bytes[bytes.size() / 2] ^= 0x10;
  std::ofstream(cp, std::ios::binary) << bytes;
  const fs::path log = dir / "corrupt.log";
  EXPECT_EQ(
      run({"run", kCoarseCase.string(), "--out", out.string(), "--quiet", "--resume"}, {}, log), 1);
  EXPECT_NE(read_text(log).find("checksum"), std::string::npos) << read_text(log);
}

}  // namespace
}  // namespace tt::reliability_test
