// thermotwin compensate end to end: a measured run fitted with fit --data --quick, then a held-out
// run replayed through compensate, from a finished file and from one that grows while it is
// followed, must give compensation.csv's predictions; a blank cell is held and flagged, and a
// stream that lacks a model's column is refused with the column named, and the observer's options
// with a fitted model are refused; a reader that falls behind costs lines (announced), never the
// pace at which the input is read.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>

#include "core/rng.hpp"
#include "fitting/features.hpp"
#include "io/measured_data.hpp"
#include "tests/common/csv_rows.hpp"
#include "tests/reliability/process.hpp"

namespace fs = std::filesystem;
using namespace tt;
using reliability_test::read_text;
using reliability_test::run;
using reliability_test::scratch;

namespace {

/// `hours` at one sample a minute: the spindle at 2500 rpm for 4 of every 6 hours; a, b, c heat
/// with 20, 50 and 100 min lags over an ambient swing; drift p = 2 µm/K Δa + 1 µm/K lp2400(Δb)
/// + 0.001 µm/rpm speed, q = −1.5 µm/K Δc + bend · Δa²; 0.1 µm noise.
io::MeasuredRun spindle_run(double hours, std::uint64_t stream, double bend_um_per_k2 = 0.0) {
  std::mt19937_64 rng = core::generator(5, stream);
  std::normal_distribution<double> noise(0.0, 0.1);
  const auto n = static_cast<Eigen::Index>(hours * 60.0);
  io::MeasuredRun r;
  r.machine = "synthetic";
  r.run = "compensate test " + std::to_string(stream);
  r.sensors = {{"a", {}}, {"b", {}}, {"c", {}}};
  r.displacements = {{"p", {}, {}}, {"q", {}, {}}};
  r.inputs = {"speed_rpm"};
  r.time = Eigen::VectorXd::LinSpaced(n, 0.0, 60.0 * static_cast<double>(n - 1));
  Eigen::VectorXd on(n), ambient(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    on(i) = std::fmod(r.time(i), 6 * 3600.0) < 4 * 3600.0 && r.time(i) >= 600.0 ? 1.0 : 0.0;
    ambient(i) = 20.0 + 0.4 * std::sin(r.time(i) / 20000.0 + static_cast<double>(stream));
  }
  r.input_values = 2500.0 * on;
  r.temperature.resize(n, 3);
  const double lags[] = {1200.0, 3000.0, 6000.0};
  for (int c = 0; c < 3; ++c)
    r.temperature.col(c) = ambient + (6.0 - c) * fitting::low_pass(r.time, on, lags[c]);
  const auto rise = [&](int c) {
    return Eigen::VectorXd(r.temperature.col(c).array() - r.temperature(0, c));
  };
  const Eigen::VectorXd p =
      2.0 * rise(0) + fitting::low_pass(r.time, rise(1), 2400.0) + 0.001 * r.input_values.col(0);
  r.displacement.resize(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    r.displacement(i, 0) = (p(i) + noise(rng)) * 1e-6;
    r.displacement(i, 1) =
        (-1.5 * rise(2)(i) + bend_um_per_k2 * rise(0)(i) * rise(0)(i) + noise(rng)) * 1e-6;
  }
  return r;
}

using tt::test::csv_rows;

/// A fitted model of a training run, and a held-out run of one speed cycle (one test group,
/// re-zeroed at the run's start as compensate's increments are).
struct Fitted {
  fs::path dir, fit, test_run;
};

/// The runs (q bent by `bend`) in scratch folder `name`, fitted with fit --data --quick and
/// `extra` options.
Fitted fitted_in(const std::string& name, double bend, const std::vector<std::string>& extra) {
  Fitted f;
  f.dir = scratch(name);
  io::write_measured_run(f.dir / "train", spindle_run(30.0, 1, bend));
  f.test_run = f.dir / "test";
  io::write_measured_run(f.test_run, spindle_run(5.5, 2, bend));
  f.fit = f.dir / "fit";
  std::vector<std::string> args{"fit",
                                "--data",
                                (f.dir / "train").string(),
                                "--test",
                                f.test_run.string(),
                                "--out",
                                f.fit.string(),
                                "--quick",
                                "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  EXPECT_EQ(run(args, {}, f.dir / "fit.log"), 0) << read_text(f.dir / "fit.log");
  return f;
}

const Fitted& fitted() {
  static const Fitted f = fitted_in("compensate", 0.0, {});
  return f;
}

/// The lines of a text file, without their line breaks.
std::vector<std::string> lines_of(const fs::path& file) {
  std::istringstream text(read_text(file));
  std::vector<std::string> lines;
  for (std::string l; std::getline(text, l);) lines.push_back(l);
  return lines;
}

/// compensation.csv's predicted_um keyed by (target, time_s).
std::map<std::pair<std::string, double>, double> offline(const Fitted& f) {
  std::map<std::pair<std::string, double>, double> out;
  for (const auto& r : csv_rows(f.fit / "compensation.csv"))
    out[{r.at("target"), std::stod(r.at("time_s"))}] = std::stod(r.at("predicted_um"));
  return out;
}

/// Every output row before `before_s` matches compensation.csv to `relative` of the largest
/// prediction (compensation.csv has 10 significant digits; a network computes in float32, whose
/// results differ by its rounding between one window and a batch); returns the number of values
/// compared.
int expect_offline_predictions(const fs::path& live_csv, const Fitted& f,
                               double before_s = std::numeric_limits<double>::infinity(),
                               double relative = 1e-9) {
  const auto off = offline(f);
  double scale = 0.0;
  for (const auto& [key, v] : off) scale = std::max(scale, std::abs(v));
  EXPECT_GT(scale, 5.0);  // the models do predict a drift of several µm
  int compared = 0;
  for (const auto& r : csv_rows(live_csv)) {
    if (r.at("status") != "ok" || !(std::stod(r.at("time_s")) < before_s)) continue;
    for (const std::string target : {"p", "q"}) {
      const auto it = off.find({target, std::stod(r.at("time_s"))});
      if (it == off.end()) continue;
      EXPECT_NEAR(std::stod(r.at(target + "_predicted_um")), it->second, relative * scale)
          << target << " at " << r.at("time_s");
      EXPECT_GT(std::stod(r.at(target + "_sigma_um")), 0.0);
      ++compared;
    }
  }
  return compared;
}

}  // namespace

TEST(Compensate, ReplayedRunGivesTheOfflinePredictions) {
  const Fitted& f = fitted();
  const fs::path live = f.dir / "replay.csv";
  ASSERT_EQ(run({"compensate", "--model", (f.fit / "fit.json").string(), "--in",
                 (f.test_run / "data.csv").string(), "--until-eof", "--out", live.string()},
                {}, f.dir / "replay.log"),
            0)
      << read_text(f.dir / "replay.log");
  EXPECT_EQ(csv_rows(live).size(), 330u);
  EXPECT_EQ(expect_offline_predictions(live, f), 2 * 330);
}

TEST(Compensate, TheNetworkFitChoseIsReplayedAsOffline) {
  // q bends with the square of a's rise, which no linear candidate has: fit --data --network
  // chooses the network for it. compensate reads network_q.pt beside fit.json and, evaluating it
  // at every sample (as at the default period on a stream a minute apart), gives
  // compensation.csv's predictions; without the file it refuses, naming it, and writes nothing.
  const Fitted f = fitted_in("compensate_network", 0.4, {"--network"});
  const auto fit = nlohmann::json::parse(read_text(f.fit / "fit.json"));
  ASSERT_EQ(fit["targets"][1]["target"], "q");
  ASSERT_EQ(fit["targets"][1]["chosen"]["coefficients"]["kind"], "cnn_bigru_attention")
      << "the test's premise: the network is q's chosen model";
  EXPECT_GT(fit["targets"][1]["chosen"]["coefficients"]["training"]["best_epoch"], 0);
  const fs::path live = f.dir / "replay.csv", log = f.dir / "replay.log";
  for (const std::string every : {"0", "1"}) {
    ASSERT_EQ(run({"compensate", "--model", (f.fit / "fit.json").string(), "--in",
                   (f.test_run / "data.csv").string(), "--until-eof", "--out", live.string(),
                   "--network-every-s", every},
                  {}, log),
              0)
        << read_text(log);
    EXPECT_EQ(expect_offline_predictions(live, f, std::numeric_limits<double>::infinity(), 1e-6),
              2 * 330)
        << every;
  }
  fs::rename(f.fit / "network_q.pt", f.dir / "away.pt");
  fs::remove(live);
  EXPECT_NE(run({"compensate", "--model", (f.fit / "fit.json").string(), "--in",
                 (f.test_run / "data.csv").string(), "--until-eof", "--out", live.string()},
                {}, log),
            0);
  EXPECT_NE(read_text(log).find("network_q.pt"), std::string::npos) << read_text(log);
  EXPECT_FALSE(fs::exists(live));
}

TEST(Compensate, ALoggersOwnColumnNamesAreReadAsTheModelsWhenMapped) {
  // The held-out run with a logger's names for sensor a and the speed: refused as it is, naming
  // the column the model reads; read with --column under the model's names, the offline
  // predictions. A mapping to a column the stream lacks, or onto one it has, or not of the form
  // MODEL=STREAM, is refused naming it, and nothing is written.
  const Fitted& f = fitted();
  std::string text = read_text(f.test_run / "data.csv");
  const std::string header = text.substr(0, text.find('\n'));
  ASSERT_EQ(header, "time_s,speed_rpm,a,b,c,p,q");
  const fs::path renamed = f.dir / "logger.csv", live = f.dir / "logger_live.csv";
  std::ofstream(renamed) << "time_s,spindle,ch_a,b,c,p,q" << text.substr(header.size());
  const fs::path log = f.dir / "logger.log";
  const std::vector<std::string> base{"compensate", "--model",        (f.fit / "fit.json").string(),
                                      "--in",       renamed.string(), "--until-eof",
                                      "--out",      live.string()};
  EXPECT_NE(run(base, {}, log), 0);
  EXPECT_NE(read_text(log).find("column 'a' is missing"), std::string::npos) << read_text(log);
  std::vector<std::string> mapped = base;
  mapped.insert(mapped.end(), {"--column", "a=ch_a", "--column", "speed_rpm=spindle"});
  ASSERT_EQ(run(mapped, {}, log), 0) << read_text(log);
  EXPECT_EQ(expect_offline_predictions(live, f), 2 * 330);
  for (const auto& [alias, message] :
       {std::pair<std::string, std::string>{"a=nope", "the stream has no column 'nope'"},
        {"b=ch_a", "the stream has a column 'b' already"},
        {"a", "expected MODEL=STREAM"}}) {
    std::vector<std::string> bad = base;
    bad.insert(bad.end(), {"--column", alias});
    fs::remove(live);
    EXPECT_NE(run(bad, {}, log), 0) << alias;
    EXPECT_NE(read_text(log).find(message), std::string::npos) << read_text(log);
    EXPECT_FALSE(fs::exists(live)) << alias;
  }
}

TEST(Compensate, FollowsAGrowingFileAndHoldsABlankCell) {
  const Fitted& f = fitted();
  const std::vector<std::string> lines = lines_of(f.test_run / "data.csv");
  const fs::path growing = f.dir / "growing.csv", live = f.dir / "followed.csv";
  {
    std::ofstream out(growing);
    for (std::size_t i = 0; i < 50; ++i) out << lines[i] << "\n";
  }
  const pid_t pid =
      reliability_test::start({"compensate", "--model", (f.fit / "fit.json").string(), "--in",
                               growing.string(), "--idle-s", "1.5", "--out", live.string()},
                              {}, f.dir / "follow.log");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  {
    std::ofstream out(growing, std::ios::app);
    // Line 60's (sample 59's) reading of c is lost; half a line is written before the rest.
    for (std::size_t i = 50; i < lines.size(); ++i) {
      std::string l = lines[i];
      if (i == 60) {
        // columns in the writer's order: time_s, speed_rpm, a, b, c, p, q
        std::vector<std::string> cells;
        std::stringstream s(l);
        for (std::string c; std::getline(s, c, ',');) cells.push_back(c);
        ASSERT_EQ(cells.size(), 7u) << l;
        cells[4].clear();
        l = cells[0];
        for (std::size_t c = 1; c < cells.size(); ++c) l += "," + cells[c];
      }
      if (i == 100) {
        out << l.substr(0, 5) << std::flush;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        out << l.substr(5) << "\n";
      } else {
        out << l << "\n";
      }
    }
  }
  ASSERT_EQ(reliability_test::wait_for(pid), 0) << read_text(f.dir / "follow.log");
  const auto rows = csv_rows(live);
  ASSERT_EQ(rows.size(), lines.size() - 1);
  EXPECT_EQ(rows[59].at("status"), "held:c");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (i != 59) {
      EXPECT_EQ(rows[i].at("status"), "ok") << i;
    }
    EXPECT_FALSE(rows[i].at("p_predicted_um").empty()) << i;
  }
  // Before the gap every prediction is the offline one; from it on, the held reading of c (a
  // value the offline fit never saw: it drops the row) changes the prediction there.
  EXPECT_EQ(expect_offline_predictions(live, f, std::stod(rows[59].at("time_s"))), 2 * 59);
  const double t59 = std::stod(rows[59].at("time_s"));
  EXPECT_GT(std::abs(std::stod(rows[59].at("q_predicted_um")) - offline(f).at({"q", t59})), 1e-3);
}

/// Bytes the process has read so far (/proc/<pid>/io's rchar), -1 when it cannot be read.
long long bytes_read(pid_t pid) {
  std::ifstream io("/proc/" + std::to_string(pid) + "/io");
  std::string key;
  long long value = -1;
  while (io >> key >> value)
    if (key == "rchar:") return value;
  return -1;
}

TEST(Compensate, AReaderThatFallsBehindCostsLinesNotThePace) {
  // 200 000 samples, the output a FIFO the test does not read until compensate has read its
  // whole input: a compensate that waited for its reader would stop reading once the FIFO and
  // the 0.25 MiB it may hold were full (about 4 000 lines). The reader then gets whole lines,
  // each gap said by the line after it (dropped:N), and written and dropped lines add up.
  const Fitted& f = fitted();
  const std::vector<std::string> lines = lines_of(f.test_run / "data.csv");
  const fs::path stream = f.dir / "long.csv", fifo = f.dir / "slow_reader.fifo";
  const int samples = 200000;
  {
    std::ofstream out(stream);
    out << lines[0] << "\n";
    for (int k = 0; k < samples; ++k) {
      const std::string& l = lines[1 + static_cast<std::size_t>(k) % (lines.size() - 1)];
      out << k << l.substr(l.find(',')) << "\n";
    }
  }
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const int fd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(fd, 0);
  const pid_t pid = reliability_test::start(
      {"compensate", "--model", (f.fit / "fit.json").string(), "--in", stream.string(),
       "--until-eof", "--out", fifo.string(), "--max-behind-mib", "0.25"},
      {}, f.dir / "slow_reader.log");
  const auto size = static_cast<long long>(fs::file_size(stream));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  long long read_so_far = 0;
  while ((read_so_far = bytes_read(pid)) < size && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_GE(read_so_far, size) << "compensate stopped reading its input while its reader waited";
  ASSERT_EQ(::fcntl(fd, F_SETFL, 0), 0);  // now read, waiting for the rest
  std::string got;
  char buffer[1 << 16];
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;) got.append(buffer, n);
  ::close(fd);
  ASSERT_EQ(reliability_test::wait_for(pid), 0) << read_text(f.dir / "slow_reader.log");
  std::istringstream out(got);
  std::string line;
  ASSERT_TRUE(std::getline(out, line));
  EXPECT_EQ(line, "time_s,p_predicted_um,p_sigma_um,q_predicted_um,q_sigma_um,status");
  int expected = 0, gaps = 0, written = 0;
  for (; std::getline(out, line); ++written) {
    const std::string status = line.substr(line.rfind(',') + 1);
    const int gap = status == "ok" ? 0 : std::stoi(status.substr(status.find("dropped:") + 8));
    ASSERT_EQ(std::count(line.begin(), line.end(), ','), 5) << line;
    ASSERT_EQ(std::stoi(line.substr(0, line.find(','))), expected + gap) << line;
    gaps += gap > 0;
    expected += gap + 1;
  }
  EXPECT_EQ(expected, samples);
  EXPECT_GT(gaps, 0);
  EXPECT_LT(written, samples / 2);
}

TEST(Compensate, StreamLackingAModelColumnIsRefusedNamingIt) {
  const Fitted& f = fitted();
  const fs::path stream = f.dir / "no_b.csv";
  std::ofstream(stream) << "time_s,speed_rpm,a,c\n0,0,20,20\n";
  const fs::path log = f.dir / "refused.log", out = f.dir / "refused.csv";
  EXPECT_NE(run({"compensate", "--model", (f.fit / "fit.json").string(), "--in", stream.string(),
                 "--until-eof", "--out", out.string()},
                {}, log),
            0);
  EXPECT_NE(read_text(log).find("column 'b' is missing"), std::string::npos) << read_text(log);
  EXPECT_FALSE(fs::exists(out));
  // The physics observer's options need a reduced model: with a fitted model they are refused,
  // not ignored.
  for (const std::vector<std::string> flag :
       {std::vector<std::string>{"--sigma-calibration", stream.string()},
        std::vector<std::string>{"--widen-on-inconsistency"},
        std::vector<std::string>{"--drift-readings-every-s", "1800"}}) {
    std::vector<std::string> args{"compensate", "--model",       (f.fit / "fit.json").string(),
                                  "--in",       stream.string(), "--until-eof",
                                  "--out",      out.string()};
    args.insert(args.end(), flag.begin(), flag.end());
    EXPECT_NE(run(args, {}, log), 0) << flag.front();
    EXPECT_NE(read_text(log).find(flag.front() + " requires --rom"), std::string::npos)
        << read_text(log);
    EXPECT_FALSE(fs::exists(out));
  }
}
