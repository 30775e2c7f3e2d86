// app/plot.py draws every kind of plot from CSV files written by write_csv, and fails cleanly on
// a missing column. Skipped when /usr/bin/python3 has no matplotlib.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "io/child_process.hpp"
#include "io/csv_out.hpp"
#include "tiny_mesh.hpp"

namespace tt::io {
namespace {

namespace fs = std::filesystem;

bool matplotlib_available() {
  return fs::exists("/usr/bin/python3") &&
         run_program({"/usr/bin/python3", "-c", "import matplotlib"}, {}, "/dev/null") == 0;
}

/// Exit status of plot.py run with `arguments`; its output (only this run's) goes to `log`.
int run_plot(const std::vector<std::string>& arguments, const fs::path& log) {
  std::vector<std::string> argv{"/usr/bin/python3",
                                (fs::path(TT_SOURCE_DIR) / "app" / "plot.py").string()};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  fs::remove(log);
  return run_program(argv, {"MPLBACKEND=Agg", "MPLCONFIGDIR=" + log.parent_path().string()}, log);
}

bool is_png(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  char signature[8] = {};
  in.read(signature, 8);
  return in && std::string(signature, 8) == "\x89PNG\r\n\x1a\n" && fs::file_size(path) > 1000;
}

TEST(PlotScript, WritesEveryKindOfPlot) {
  if (!matplotlib_available()) GTEST_SKIP() << "/usr/bin/python3 with matplotlib not found";
  const auto dir = test::scratch_dir("plot");
  const int n = 40;
  Eigen::MatrixXd rows(n, 5);
  for (int i = 0; i < n; ++i) {
    const double t = 180.0 * i;
    rows.row(i) << t, 20.0 + 8.0 * (1.0 - std::exp(-t / 3000.0)),
        20.0 + 5.0 * (1.0 - std::exp(-t / 5000.0)), -12.0 * (1.0 - std::exp(-t / 4000.0)),
        30.0 * (1.0 - std::exp(-t / 4000.0));
  }
  write_csv(dir / "history.csv", {"time_s", "T02_degC", "T10_degC", "dy_um", "dz_um"}, rows);
  {
    std::ofstream bars(dir / "scores.csv");
    bars << "id,mi_bits_dy\nT02,1.5\nT10,0.75\nT18,2.25\n";
  }
  const auto csv = (dir / "history.csv").string();
  const auto log = dir / "plot.log";

  EXPECT_EQ(run_plot({"temperatures", csv, (dir / "t.png").string(), "--columns",
                      "T02_degC,T10_degC", "--rise-from-first", "--title", "Warm-up"},
                     log),
            0);
  EXPECT_TRUE(is_png(dir / "t.png"));
  EXPECT_EQ(
      run_plot({"thermal_error", csv, (dir / "e.png").string(), "--columns", "dy_um,dz_um"}, log),
      0);
  EXPECT_TRUE(is_png(dir / "e.png"));
  EXPECT_EQ(
      run_plot({"lines", csv, (dir / "l.png").string(), "--x", "time_s", "--columns", "dy_um"},
               log),
      0);
  EXPECT_TRUE(is_png(dir / "l.png"));
  EXPECT_EQ(run_plot({"bars", (dir / "scores.csv").string(), (dir / "b.png").string(), "--label",
                      "id", "--value", "mi_bits_dy", "--sort"},
                     log),
            0);
  EXPECT_TRUE(is_png(dir / "b.png"));
}

TEST(PlotScript, MissingColumnFailsWithoutWritingAnImage) {
  if (!matplotlib_available()) GTEST_SKIP() << "/usr/bin/python3 with matplotlib not found";
  const auto dir = test::scratch_dir("plot_bad");
  write_csv(dir / "h.csv", {"time_s", "T02_degC"}, Eigen::MatrixXd::Ones(3, 2));
  const auto log = dir / "plot.log";
  EXPECT_EQ(run_plot({"temperatures", (dir / "h.csv").string(), (dir / "t.png").string(),
                      "--columns", "T02_degC,T99_degC"},
                     log),
            2);
  EXPECT_FALSE(fs::exists(dir / "t.png"));
  EXPECT_FALSE(fs::exists(dir / "t.png.tmp"));
  std::ifstream in(log);
  const std::string message((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(message.find("T99_degC"), std::string::npos) << message;
}

}  // namespace
}  // namespace tt::io
