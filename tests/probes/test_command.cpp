#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/errors.hpp"
#include "probe_fixtures.hpp"
#include "probes/command.hpp"
#include "tests/common/output_schema.hpp"

using namespace tt::probes;
namespace fs = std::filesystem;

namespace {

std::string first_line(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  return line;
}

/// A fresh output folder: run_probes_command writes into it (the CLI publishes it whole).
fs::path out_dir(const fs::path& dir) {
  fs::create_directories(dir / "out");
  return dir / "out";
}

const MethodSummary& method(const ProbeRunSummary& s, AlignmentMethod m) {
  for (const MethodSummary& x : s.methods)
    if (x.method == m) return x;
  throw std::runtime_error("method missing from the summary");
}

}  // namespace

TEST(ProbesCommand, RunsOnAVirtualRawFileAndShowsTheGainOfAlignment) {
  const fs::path dir = fixtures::scratch_dir("command_virtual");
  const DriftHistory h = fixtures::warm_up_history();
  write_virtual_raw_csv(dir / "raw.csv", fixtures::runout_setup(51), h, dir / "truth.csv");
  ProbeOptions options;
  options.truth_csv = dir / "truth.csv";
  const ProbeRunSummary s = run_probes_command(dir / "raw.csv", out_dir(dir), options);

  EXPECT_EQ(s.readings, h.size());
  EXPECT_EQ(s.plan.window_samples, 200);
  for (const char* f : {"drift.csv", "drift_xcorr.csv", "drift_noalign.csv", "drift_revmean.csv",
                        "alignment.csv", "summary.json"})
    EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
  EXPECT_TRUE(tt::test::matches_output_schemas("probes", dir / "out"));
  EXPECT_EQ(first_line(dir / "out" / "drift.csv"),
            "time_s,x1_um,y1_um,x2_um,y2_um,tilt_x_urad,tilt_y_urad");

  const auto& info = method(s, AlignmentMethod::information_distance);
  ASSERT_TRUE(info.error_vs_truth);
  EXPECT_LT(info.error_vs_truth->max_drift_m, 0.3e-6);
  EXPECT_LT(info.error_vs_truth->max_tilt_rad, 2e-6);
  EXPECT_GT(method(s, AlignmentMethod::none).error_vs_truth->max_drift_m, 2.5e-6);
  EXPECT_LT(method(s, AlignmentMethod::cross_correlation).error_vs_truth->max_drift_m, 0.3e-6);

  // drift.csv itself, read back, matches the truth.
  const DriftHistory got = read_drift_history_csv(dir / "out" / "drift.csv");
  const DriftSeries truth = drift_relative_to_first(h, 0.15, false);
  ASSERT_EQ(got.size(), h.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_NEAR(got[i].drift.x2_m, truth.points[i].drift.x2_m, 0.3e-6);
    EXPECT_NEAR(got[i].drift.y1_m, truth.points[i].drift.y1_m, 0.3e-6);
  }
  std::ifstream json(dir / "out" / "summary.json");
  std::stringstream text;
  text << json.rdbuf();
  EXPECT_NE(text.str().find("\"noalign\": {\"file\": \"drift_noalign.csv\""), std::string::npos)
      << text.str();
  EXPECT_NE(text.str().find("max_drift_error_um"), std::string::npos);

  // A second run over the same folder rewrites every file.
  EXPECT_NO_THROW(run_probes_command(dir / "raw.csv", dir / "out", {}));
}

TEST(ProbesCommand, AxialProbeAddsZ) {
  const fs::path dir = fixtures::scratch_dir("command_axial");
  VirtualProbeSetup setup = fixtures::runout_setup(52);
  setup.axial_probe = true;
  write_virtual_raw_csv(dir / "raw.csv", setup, fixtures::warm_up_history(4), dir / "truth.csv");
  ProbeOptions options;
  options.truth_csv = dir / "truth.csv";
  const ProbeRunSummary s = run_probes_command(dir / "raw.csv", out_dir(dir), options);
  EXPECT_TRUE(s.has_axial);
  EXPECT_EQ(first_line(dir / "out" / "drift.csv"),
            "time_s,x1_um,y1_um,x2_um,y2_um,tilt_x_urad,tilt_y_urad,z_um");
  EXPECT_LT(method(s, AlignmentMethod::information_distance).error_vs_truth->max_drift_m, 0.3e-6);
}

// Which output folders the CLI replaces is io::OutputDir's rule (tests/reliability).
TEST(ProbesCommand, BadInputWritesNothing) {
  const fs::path dir = fixtures::scratch_dir("command_bad");
  std::ofstream(dir / "raw.csv")
      << "# speed_rpm=6000 sample_rate_hz=1000 probe_distance_mm=150\n"
         "reading,time_s,sample,s1_um,s2_um,s3_um,s4_um\n1,0,0,1,2,3,oops\n";
  try {
    run_probes_command(dir / "raw.csv", out_dir(dir), {});
    FAIL() << "malformed input accepted";
  } catch (const tt::core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("raw.csv:3: column 7 (s4_um)"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(fs::is_empty(dir / "out"));
}
