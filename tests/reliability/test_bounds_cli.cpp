// Issue 14 at the command line: numbers that make no sense are refused by the option's name
// before any work starts, and killing thermotwin while TetGen meshes leaves no TetGen behind.
#include <dirent.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/reliability/process.hpp"

namespace tt::reliability_test {
namespace {

/// Exit code and output of thermotwin `args`.
std::pair<int, std::string> run_logged(const std::vector<std::string>& args, const fs::path& log) {
  const int code = run(args, {}, log);
  return {code, read_text(log)};
}

TEST(BoundsCli, NonFiniteNumbersAreRefusedByTheOptionsName) {
  const fs::path dir = scratch("bounds_cli_numbers");
  const std::string c = kCoarseCase.string();
  const std::string out = (dir / "out").string();
  const struct {
    std::vector<std::string> args;
    const char* option;
  } cases[] = {
      {{"run", c, "--out", out, "--checkpoint-every-s", "nan"}, "--checkpoint-every-s"},
      {{"fit", c, "--out", out, "--hours", "nan"}, "--hours"},
      {{"fit", c, "--out", out, "--hours", "inf"}, "--hours"},
      {{"fit", c, "--out", out, "--hours", "-1"}, "--hours"},
      {{"fit", c, "--out", out, "--required-sm-um", "nan"}, "--required-sm-um"},
      {{"fit", "--data", dir.string(), "--out", out, "--test-from-s", "nan"}, "--test-from-s"},
      {{"fit", "--data", dir.string(), "--out", out, "--test-to-s", "-inf"}, "--test-to-s"},
      {{"calibrate", "--train", dir.string(), "--test", dir.string(), "--out", out, "--split-s",
        "nan"},
       "--split-s"},
      {{"probes", "--in", c, "--out", out, "--speed-rpm", "nan"}, "--speed-rpm"},
  };
  int i = 0;
  for (const auto& k : cases) {
    const auto [code, text] = run_logged(k.args, dir / ("log" + std::to_string(i++)));
    EXPECT_NE(code, 0) << k.option;
    EXPECT_NE(text.find(k.option), std::string::npos) << text;
    EXPECT_NE(text.find("finite"), std::string::npos) << text;
    EXPECT_FALSE(fs::exists(out)) << k.option;
  }
}

TEST(BoundsCli, TetGenIsRefusedMemoryBeyondTheLimit) {
  // A fresh process: the TetGen child may reuse what it inherits (free heap, cached stacks), and
  // SB-1's default mesh needs far more than that and 2 MB beyond it.
  const fs::path dir = scratch("bounds_cli_memory");
  std::string text = read_text(fs::path(TT_SOURCE_DIR) / "cases" / "sb1.toml");
  const std::string key = "min_dihedral_deg = 12.0\n";
  text.replace(text.find(key), key.size(), key + "memory_limit_GB = 0.002\n");
  std::ofstream(dir / "case.toml") << text;
  const auto [code, log] = run_logged(
      {"mesh", (dir / "case.toml").string(), "--out", (dir / "out").string()}, dir / "log");
  EXPECT_EQ(code, 1) << log;
  EXPECT_NE(log.find("mesh.memory_limit_GB = 0.002"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

/// Processes whose parent is `parent` (from /proc/*/stat).
std::vector<pid_t> children_of(pid_t parent) {
  std::vector<pid_t> out;
  DIR* proc = opendir("/proc");
  if (!proc) return out;
  while (const dirent* e = readdir(proc)) {
    const pid_t pid = static_cast<pid_t>(std::atoi(e->d_name));
    if (pid <= 0) continue;
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string text;
    std::getline(stat, text);
    const auto close = text.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(text.substr(close + 2));
    char state = 0;
    pid_t ppid = 0;
    rest >> state >> ppid;
    if (ppid == parent && state != 'Z') out.push_back(pid);
  }
  closedir(proc);
  return out;
}

bool alive(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  std::getline(stat, text);
  const auto close = text.rfind(')');
  return close != std::string::npos && text.size() > close + 2 && text[close + 2] != 'Z';
}

TEST(BoundsCli, KillingThermotwinWhileItMeshesEndsTetGen) {
  using namespace std::chrono_literals;
  const fs::path dir = scratch("bounds_cli_kill_mesh");
  // The default SB-1 mesh: several seconds of TetGen.
  const pid_t parent = start({"mesh", (fs::path(TT_SOURCE_DIR) / "cases" / "sb1.toml").string(),
                              "--out", (dir / "out").string()});
  std::vector<pid_t> tetgen;
  for (auto waited = 0ms; waited < 60s && tetgen.empty(); waited += 20ms) {
    std::this_thread::sleep_for(20ms);
    tetgen = children_of(parent);
  }
  ASSERT_EQ(tetgen.size(), 1u) << "no TetGen child appeared";
  ::kill(parent, SIGKILL);
  wait_for(parent);
  bool gone = false;
  for (auto waited = 0ms; waited < 2s && !gone; waited += 20ms) {
    gone = !alive(tetgen[0]);
    if (!gone) std::this_thread::sleep_for(20ms);
  }
  if (!gone) ::kill(tetgen[0], SIGKILL);  // leave nothing running, whatever the result
  EXPECT_TRUE(gone) << "TetGen (pid " << tetgen[0] << ") outlived its parent";
}

}  // namespace
}  // namespace tt::reliability_test
