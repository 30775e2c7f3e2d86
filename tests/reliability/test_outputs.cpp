// Nothing a user passes runs a command or removes a file they did not ask to replace, and one
// command at a time writes an output (docs/reliability.md, "What --out may replace"). The runs
// are the real CLI on the coarse SB-1 case and on a copy of data/fl-thermal-measured.
#include <gtest/gtest.h>

#include <fstream>

#include "tests/reliability/process.hpp"

namespace tt::reliability_test {
namespace {

using Clock = std::chrono::steady_clock;

const fs::path kMeasuredRun = fs::path(TT_SOURCE_DIR) / "data" / "fl-thermal-measured";

void put(const fs::path& file, const std::string& text) {
  std::ofstream(file) << text;
}

fs::path with_suffix(const fs::path& p, const char* suffix) {
  fs::path s = p;
  s += suffix;
  return s;
}

void replace_once(std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
}

/// `s` as a TOML basic string.
std::string toml_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '\n')
      out += "\\n";
    else if (c == '"' || c == '\\')
      out += std::string("\\") + c;
    else
      out += c;
  }
  return out + "\"";
}

/// The coarse case written to `dir`/case.toml, with another name and, unless `fields`, no field
/// files (the slowest output, not needed by most checks).
fs::path coarse_case(const fs::path& dir, const std::string& name = "coarse", bool fields = false) {
  std::string text = read_text(kCoarseCase);
  replace_once(text, "name = \"SB-1 P-1 (coarse mesh)\"", "name = " + toml_string(name));
  if (!fields) replace_once(text, "[outputs]\n", "[outputs]\nfields = false\n");
  const fs::path file = dir / "case.toml";
  put(file, text);
  return file;
}

/// Waits until `file` exists or the child ends; true when it exists.
bool wait_for_path(const fs::path& file, pid_t pid) {
  for (;;) {
    std::error_code ec;
    if (fs::exists(file, ec)) return true;
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

/// Waits until a result file (not the marker) appears in `dir`; false when the child ended first.
bool wait_for_result_file(const fs::path& dir, pid_t pid) {
  for (;;) {
    std::error_code ec;
    if (fs::is_directory(dir, ec))
      for (const auto& e : fs::directory_iterator(dir, ec))
        if (e.is_regular_file(ec) && e.path().filename().string().rfind(".thermotwin", 0) != 0)
          return true;
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

int occurrences(const std::string& text, const std::string& part) {
  int n = 0;
  for (auto at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

// ---- 1. No shell: quotes, $(...), backticks and newlines are only characters. ----

/// A payload that runs `touch <marker>` under any shell quoting of the three usual kinds.
std::string payload(const std::string& marker) {
  return "x';touch " + marker + "_q;'$(touch " + marker + "_d)`touch " + marker + "_b`";
}

/// Every file a payload could have made, in the folders a shell would have run it in.
std::vector<fs::path> markers_made(const fs::path& dir, const std::string& marker) {
  std::vector<fs::path> found;
  for (const fs::path& where : {fs::current_path(), dir})
    for (const char* s : {"_q", "_d", "_b"})
      if (fs::exists(where / (marker + s))) found.push_back(where / (marker + s));
  return found;
}

TEST(NoShell, CaseNameAndOutPathRunNothingAndTheFiguresAreMade) {
  const fs::path dir = scratch("noshell_run");
  const std::string name = payload("PWNED_name") + "\nsecond line";
  const fs::path out = dir / (payload("PWNED_out") + "\nz");
  const fs::path log = dir / "log.txt";
  ASSERT_EQ(
      run({"run", coarse_case(dir, name).string(), "--out", out.string(), "--quiet"}, {}, log), 0)
      << read_text(log);
  EXPECT_TRUE(markers_made(dir, "PWNED_name").empty()) << "the case's name ran a command";
  EXPECT_TRUE(markers_made(dir, "PWNED_out").empty()) << "the --out path ran a command";
  EXPECT_TRUE(fs::is_regular_file(out / "summary.json"));
  EXPECT_GT(fs::file_size(out / "temperature_rise.png"), 1000u);
  EXPECT_GT(fs::file_size(out / "thermal_error.png"), 1000u);
  EXPECT_FALSE(contains(read_text(log), "plot skipped")) << read_text(log);
}

TEST(NoShell, ChannelIdOfAMeasuredRunRunsNothingAndItsFigureIsMade) {
  // A channel id cannot hold a newline (it names a column of data.csv's one header line); the
  // reader refuses one (tests/reliability/test_hostile_data.cpp).
  const fs::path dir = scratch("noshell_channel");
  const fs::path runs = dir / "run";
  fs::create_directories(runs);
  const std::string channel = payload("PWNED_ch");
  std::string meta = read_text(kMeasuredRun / "meta.json");
  // Every "ch1" of meta.json: the channel's id and the keys of its published figure.
  const std::string quoted = "\"" + channel + "\"";
  for (auto at = meta.find("\"ch1\""); at != std::string::npos;
       at = meta.find("\"ch1\"", at + quoted.size()))
    meta.replace(at, 5, quoted);
  put(runs / "meta.json", meta);
  std::string data = read_text(kMeasuredRun / "data.csv");
  replace_once(data, ",ch1,", "," + channel + ",");
  put(runs / "data.csv", data);
  const fs::path out = dir / "fit";
  const fs::path log = dir / "log.txt";
  ASSERT_EQ(
      run({"fit", "--data", runs.string(), "--out", out.string(), "--quick", "--quiet"}, {}, log),
      0)
      << read_text(log);
  EXPECT_TRUE(markers_made(dir, "PWNED_ch").empty()) << "a channel id ran a command";
  EXPECT_GT(fs::file_size(out / ("window_" + channel + ".png")), 1000u);
  EXPECT_FALSE(contains(read_text(log), "plot skipped")) << read_text(log);
}

// ---- 2. --out replaces only an earlier result of thermotwin. ----

TEST(OutReplacesOnlyResults, AFileAtOutIsKept) {
  const fs::path dir = scratch("out_file");
  put(dir / "out", "precious\n");
  const fs::path log = dir / "log.txt";
  EXPECT_EQ(run({"mesh", coarse_case(dir).string(), "--out", (dir / "out").string()}, {}, log), 1);
  EXPECT_EQ(read_text(dir / "out"), "precious\n");
  EXPECT_TRUE(contains(read_text(log), "not a folder")) << read_text(log);
  EXPECT_TRUE(contains(read_text(log), "Hint")) << read_text(log);
  EXPECT_FALSE(fs::exists(dir / "out.partial"));
  EXPECT_FALSE(fs::exists(dir / "out.lock"));
}

TEST(OutReplacesOnlyResults, AFolderThermotwinDidNotWriteIsKept) {
  const fs::path dir = scratch("out_foreign");
  fs::create_directories(dir / "mine");
  put(dir / "mine" / "notes.txt", "keep me\n");
  const fs::path log = dir / "log.txt";
  EXPECT_EQ(run({"mesh", coarse_case(dir).string(), "--out", (dir / "mine").string()}, {}, log), 1);
  EXPECT_EQ(read_text(dir / "mine" / "notes.txt"), "keep me\n");
  EXPECT_TRUE(contains(read_text(log), ".thermotwin-result")) << read_text(log);
}

TEST(OutReplacesOnlyResults, TheFolderOfTheCaseIsKept) {
  const fs::path dir = scratch("out_cases");
  fs::create_directories(dir / "cases");
  const fs::path case_file = coarse_case(dir / "cases");
  const std::string before = read_text(case_file);
  const fs::path log = dir / "log.txt";
  EXPECT_EQ(run({"mesh", case_file.string(), "--out", (dir / "cases").string()}, {}, log), 1);
  EXPECT_EQ(read_text(case_file), before);
  EXPECT_TRUE(contains(read_text(log), "contains the input")) << read_text(log);
}

TEST(OutReplacesOnlyResults, FitDataOutThatIsTheInputRunIsRefused) {
  const fs::path dir = scratch("out_is_run");
  const fs::path runs = dir / "run";
  fs::create_directories(runs);
  for (const char* f : {"meta.json", "data.csv"}) fs::copy_file(kMeasuredRun / f, runs / f);
  const auto before = snapshot(runs);
  const fs::path log = dir / "log.txt";
  EXPECT_EQ(run({"fit", "--data", runs.string(), "--out", runs.string(), "--quick"}, {}, log), 1);
  EXPECT_TRUE(snapshot(runs) == before) << "the input run changed";
  EXPECT_TRUE(contains(read_text(log), "is the input")) << read_text(log);
  // Inside the run is refused as well: the result would sit among the run's files.
  EXPECT_EQ(
      run({"fit", "--data", runs.string(), "--out", (runs / "fit").string(), "--quick"}, {}, log),
      1);
  EXPECT_TRUE(snapshot(runs) == before);
  EXPECT_TRUE(contains(read_text(log), "lies inside the input")) << read_text(log);
}

TEST(OutReplacesOnlyResults, AUsersOwnOldFolderIsNeverTouched) {
  const fs::path dir = scratch("out_old");
  fs::create_directories(dir / "out.old");
  put(dir / "out.old" / "notes.txt", "mine\n");
  const fs::path case_file = coarse_case(dir);
  const fs::path log = dir / "log.txt";
  ASSERT_EQ(run({"mesh", case_file.string(), "--out", (dir / "out").string()}, {}, log), 0)
      << read_text(log);
  EXPECT_TRUE(fs::exists(dir / "out" / "mesh.vtu"));
  EXPECT_TRUE(fs::exists(dir / "out" / ".thermotwin-result"));
  EXPECT_FALSE(fs::exists(dir / "out" / "notes.txt")) << "out.old was taken for a result";
  // Replacing the result it wrote leaves the user's folder alone too.
  ASSERT_EQ(run({"mesh", case_file.string(), "--out", (dir / "out").string()}, {}, log), 0);
  EXPECT_EQ(read_text(dir / "out.old" / "notes.txt"), "mine\n");
  EXPECT_TRUE(fs::exists(dir / "out" / "mesh.vtu"));
}

// ---- 3. One writer per output. ----

TEST(OneWriter, ASecondCommandWithTheSameOutIsRefusedAtOnce) {
  const fs::path dir = scratch("one_writer");
  const fs::path case_file = coarse_case(dir);
  const fs::path out = dir / "out";
  const pid_t first =
      start({"run", case_file.string(), "--out", out.string(), "--quiet"}, {}, dir / "first.log");
  ASSERT_TRUE(wait_for_path(with_suffix(out, ".lock"), first)) << read_text(dir / "first.log");
  const int second =
      run({"run", case_file.string(), "--out", out.string(), "--quiet"}, {}, dir / "second.log");
  const bool first_still_running = waitpid(first, nullptr, WNOHANG) == 0;
  EXPECT_EQ(second, 1);
  EXPECT_TRUE(contains(read_text(dir / "second.log"),
                       "another thermotwin command (pid " + std::to_string(first) + ")"))
      << read_text(dir / "second.log");
  EXPECT_TRUE(first_still_running) << "the first run ended before the second was refused";
  EXPECT_EQ(wait_for(first), 0) << read_text(dir / "first.log");
  // The first run's result is whole: every file a run writes, the stamp last.
  for (const char* f : {"summary.json", "temperatures.csv", "thermal_error.csv",
                        "case.resolved.toml", "mesh.vtu", ".thermotwin-result"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  EXPECT_FALSE(fs::exists(with_suffix(out, ".partial")));
  EXPECT_FALSE(fs::exists(with_suffix(out, ".lock")));
}

// ---- 6. Trailing slash, unwritable outputs, checkpoints, signals, hostile runs. ----

TEST(OutPath, TrailingSlashIsTheSameFolder) {
  const fs::path dir = scratch("trailing_slash");
  const fs::path log = dir / "log.txt";
  ASSERT_EQ(
      run({"run", coarse_case(dir).string(), "--out", (dir / "out").string() + "/", "--quiet"}, {},
          log),
      0)
      << read_text(log);
  EXPECT_TRUE(fs::is_regular_file(dir / "out" / "summary.json"));
  EXPECT_FALSE(fs::exists(dir / "out" / ".partial"));
  EXPECT_FALSE(fs::exists(dir / "out" / ".checkpoint"));
  EXPECT_FALSE(fs::exists(dir / "out.partial"));
  EXPECT_FALSE(fs::exists(dir / "out.lock"));
}

TEST(OutPath, UnwritableOutIsRefusedBeforeTheMesh) {
  const fs::path dir = scratch("unwritable_out");
  put(dir / "file", "a file, not a folder\n");
  const fs::path log = dir / "log.txt";
  // Not --quiet: the mesh's progress line would show that work began.
  EXPECT_EQ(
      run({"run", coarse_case(dir).string(), "--out", (dir / "file" / "out").string()}, {}, log),
      1);
  EXPECT_TRUE(contains(read_text(log), (dir / "file").string())) << read_text(log);
  EXPECT_FALSE(contains(read_text(log), "thermotwin: mesh:")) << read_text(log);
  EXPECT_EQ(read_text(dir / "file"), "a file, not a folder\n");
}

TEST(Checkpoint, ReadOnlyCheckpointIsRefusedBeforeTheMesh) {
  const fs::path dir = scratch("readonly_checkpoint");
  const fs::path checkpoint = dir / "out.checkpoint";
  put(checkpoint, "an earlier checkpoint\n");
  fs::permissions(checkpoint, fs::perms::owner_read | fs::perms::group_read);
  const fs::path log = dir / "log.txt";
  EXPECT_EQ(run({"run", coarse_case(dir).string(), "--out", (dir / "out").string()}, {}, log), 1);
  EXPECT_TRUE(contains(read_text(log), "read-only")) << read_text(log);
  EXPECT_FALSE(contains(read_text(log), "thermotwin: mesh:")) << read_text(log);
  EXPECT_EQ(read_text(checkpoint), "an earlier checkpoint\n");
  EXPECT_FALSE(fs::exists(dir / "out.partial"));
}

TEST(Checkpoint, ASaveThatFailsWarnsAndTheRunGoesOn) {
  const fs::path dir = scratch("checkpoint_fails");
  const fs::path out = dir / "out";
  const fs::path checkpoint = with_suffix(out, ".checkpoint");
  const fs::path tmp = with_suffix(checkpoint, ".tmp");
  const fs::path log = dir / "log.txt";
  const pid_t pid = start({"run", coarse_case(dir).string(), "--out", out.string(), "--quiet",
                           "--checkpoint-every-s", "0"},
                          {}, log);
  ASSERT_TRUE(wait_for_path(checkpoint, pid)) << read_text(log);
  // A folder where the next save writes its temporary file: that save fails.
  std::error_code ec;
  while (!fs::create_directory(tmp, ec) && waitpid(pid, nullptr, WNOHANG) == 0) {
  }
  ASSERT_TRUE(fs::is_directory(tmp)) << "the run ended before a save could be made to fail";
  EXPECT_EQ(wait_for(pid), 0) << read_text(log);
  EXPECT_EQ(occurrences(read_text(log), "warning: checkpoint not saved"), 1) << read_text(log);
  EXPECT_TRUE(fs::exists(out / ".thermotwin-result"));
  EXPECT_FALSE(fs::exists(tmp)) << "a failed save left " << tmp;
  EXPECT_FALSE(fs::exists(checkpoint)) << "the checkpoint outlived a finished run";
}

TEST(Signals, InterruptWhileResultsAreWrittenLeavesThePreviousResultAndNoPartial) {
  const fs::path dir = scratch("sigint_writing");
  const fs::path case_file = coarse_case(dir, "coarse", /*fields=*/true);
  const fs::path out = dir / "out";
  ASSERT_EQ(run({"run", case_file.string(), "--out", out.string(), "--quiet"}), 0);
  const auto previous = snapshot(out);
  for (const int sig : {SIGINT, SIGTERM}) {
    const pid_t pid = start({"run", case_file.string(), "--out", out.string(), "--quiet"});
    ASSERT_TRUE(wait_for_result_file(with_suffix(out, ".partial"), pid))
        << "the run ended before writing its results";
    kill(pid, sig);
    EXPECT_EQ(wait_for(pid), 128 + sig);
    EXPECT_FALSE(fs::exists(with_suffix(out, ".partial"))) << "signal " << sig;
    EXPECT_FALSE(fs::exists(with_suffix(out, ".lock"))) << "signal " << sig;
    EXPECT_TRUE(snapshot(out) == previous) << "signal " << sig;
  }
}

TEST(Signals, InterruptDuringTheSolveLeavesOnlyTheCheckpoint) {
  const fs::path dir = scratch("sigint_solve");
  const fs::path out = dir / "out";
  const fs::path checkpoint = with_suffix(out, ".checkpoint");
  const pid_t pid = start({"run", coarse_case(dir).string(), "--out", out.string(), "--quiet",
                           "--checkpoint-every-s", "0"});
  ASSERT_TRUE(wait_for_path(checkpoint, pid)) << "the run ended before its first checkpoint";
  kill(pid, SIGINT);
  EXPECT_EQ(wait_for(pid), 128 + SIGINT);
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(with_suffix(out, ".partial")));
  EXPECT_FALSE(fs::exists(with_suffix(out, ".lock")));
  EXPECT_TRUE(fs::is_regular_file(checkpoint)) << "--resume has nothing to continue from";
}

TEST(HostileRuns, MetaJsonThatIsAFolderIsADataErrorNamingIt) {
  const fs::path dir = scratch("meta_folder");
  const fs::path runs = dir / "run";
  fs::create_directories(runs / "meta.json");
  fs::copy_file(kMeasuredRun / "data.csv", runs / "data.csv");
  const fs::path log = dir / "log.txt";
  EXPECT_EQ(run({"fit", "--data", runs.string(), "--out", (dir / "fit").string()}, {}, log), 1);
  EXPECT_TRUE(contains(read_text(log), (runs / "meta.json").string() + ": a folder"))
      << read_text(log);
  EXPECT_FALSE(contains(read_text(log), "unexpected")) << read_text(log);
}

TEST(HostileRuns, TheSameRunGivenTwiceIsRefusedNamingIt) {
  const fs::path dir = scratch("run_twice");
  const fs::path runs = kMeasuredRun;
  const fs::path log = dir / "log.txt";
  const std::string again = (runs / "." / "").string();  // another spelling of the same folder
  EXPECT_EQ(run({"fit", "--data", runs.string(), again, "--out", (dir / "fit").string()}, {}, log),
            1);
  EXPECT_TRUE(contains(read_text(log), "given twice as --data")) << read_text(log);
  EXPECT_TRUE(contains(read_text(log), runs.string())) << read_text(log);
  EXPECT_EQ(run({"calibrate", "--train", runs.string(), "--train", runs.string(), "--test",
                 runs.string(), "--out", (dir / "cal").string()},
                {}, log),
            1);
  EXPECT_TRUE(contains(read_text(log), "given twice as --train")) << read_text(log);
  // Held out and trained on at once: fit --data does not split a run.
  EXPECT_EQ(run({"fit", "--data", runs.string(), "--test", again, "--out", (dir / "fit").string()},
                {}, log),
            1);
  EXPECT_TRUE(contains(read_text(log), "given as --data and as --test")) << read_text(log);
  EXPECT_FALSE(fs::exists(dir / "fit"));
  EXPECT_FALSE(fs::exists(dir / "cal"));
}

}  // namespace
}  // namespace tt::reliability_test
