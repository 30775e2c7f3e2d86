// A run killed at any moment leaves at DIR either the previous complete result or none: never a
// half-written directory that looks whole. The runs are the real CLI on the coarse SB-1 case.
#include <gtest/gtest.h>

#include "tests/reliability/process.hpp"

namespace tt::reliability_test {
namespace {

using Clock = std::chrono::steady_clock;

/// Waits until a result file appears in `dir` (or the child ends); true when one did. The marker
/// .thermotwin-partial, there from the start, does not count.
bool wait_for_first_file(const fs::path& dir, pid_t pid) {
  for (;;) {
    std::error_code ec;
    if (fs::is_directory(dir, ec))
      for (const auto& e : fs::directory_iterator(dir, ec))
        if (e.is_regular_file(ec) && e.path().filename() != ".thermotwin-partial") return true;
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

TEST(Kill, AfterFirstOutputFileNoResultAppears) {
  const fs::path dir = scratch("kill_fresh");
  const fs::path out = dir / "run";
  const pid_t pid = start({"run", kCoarseCase.string(), "--out", out.string(), "--quiet"});
  fs::path partial = out;
  partial += ".partial";
  ASSERT_TRUE(wait_for_first_file(partial, pid)) << "the run ended before writing into " << partial;
  kill(pid, SIGKILL);
  EXPECT_EQ(wait_for(pid), 128 + SIGKILL);
  EXPECT_FALSE(fs::exists(out)) << "a killed first run left " << out;
}

TEST(Kill, AfterFirstOutputFileThePreviousResultStaysWhole) {
  const fs::path dir = scratch("kill_previous");
  const fs::path out = dir / "run";
  ASSERT_EQ(run({"run", kCoarseCase.string(), "--out", out.string(), "--quiet"}), 0);
  const auto previous = snapshot(out);
  ASSERT_TRUE(previous.count("summary.json") && previous.count("temperatures.csv"));

  const pid_t pid = start({"run", kCoarseCase.string(), "--out", out.string(), "--quiet"});
  fs::path partial = out;
  partial += ".partial";
  ASSERT_TRUE(wait_for_first_file(partial, pid));
  kill(pid, SIGKILL);
  EXPECT_EQ(wait_for(pid), 128 + SIGKILL);
  EXPECT_TRUE(snapshot(out) == previous) << "the previous result changed under a killed run";

  // The next run starts over cleanly and publishes a whole result.
  ASSERT_EQ(run({"run", kCoarseCase.string(), "--out", out.string(), "--quiet"}), 0);
  const auto again = snapshot(out);
  EXPECT_EQ(again.size(), previous.size());
  EXPECT_EQ(again.at("temperatures.csv"), previous.at("temperatures.csv"));
  fs::path partial_left = out;
  partial_left += ".partial";
  EXPECT_FALSE(fs::exists(partial_left));
}

// Kills at moments spread over a whole run, the publishing included: DIR is always the
// previous result or a new whole one, with the same files and the same numbers.
TEST(Kill, AtSpreadMomentsDirIsAlwaysWhole) {
  const fs::path dir = scratch("kill_spread");
  const fs::path out = dir / "run";
  const auto t0 = Clock::now();
  ASSERT_EQ(run({"run", kCoarseCase.string(), "--out", out.string(), "--quiet"}), 0);
  const double run_s = std::chrono::duration<double>(Clock::now() - t0).count();
  const auto previous = snapshot(out);
  int killed = 0;
  for (int k = 1; k <= 6; ++k) {
    const pid_t pid = start({"run", kCoarseCase.string(), "--out", out.string(), "--quiet"});
    std::this_thread::sleep_for(std::chrono::duration<double>(run_s * (0.55 + 0.08 * k)));
    killed += kill(pid, SIGKILL) == 0;
    wait_for(pid);
    const auto now = snapshot(out);
    ASSERT_EQ(now.size(), previous.size()) << "kill " << k << " left a directory with other files";
    for (const auto& [name, bytes] : previous) {
      ASSERT_TRUE(now.count(name)) << name << " missing after kill " << k;
      // Numbers must agree; summary.json (timings) and images may differ from run to run.
      const auto ext = fs::path(name).extension();
      if (ext == ".csv" || ext == ".toml")
        EXPECT_EQ(now.at(name), bytes) << name << " differs after kill " << k;
    }
  }
  EXPECT_GT(killed, 0);
}

}  // namespace
}  // namespace tt::reliability_test
