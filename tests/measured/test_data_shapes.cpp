// fit --data and calibrate without --case on every run shape a shop floor gives, end to end
// through the CLI: one long run with no speed column (no "inputs" key, or "inputs": []), one run
// with speed cycles, three or more runs, days as runs with held-out days; refusals that name
// their cause; and the library's guards: no compensation chosen when nothing beats it, claims
// thresholds never negative.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>

#include "core/rng.hpp"
#include "core/units.hpp"
#include "fitting/features.hpp"
#include "fitting/residual_study.hpp"
#include "fitting/segments.hpp"
#include "io/measured_data.hpp"
#include "io/measured_segments.hpp"
#include "tests/common/output_schema.hpp"
#include "tests/reliability/process.hpp"

namespace fs = std::filesystem;
using namespace tt;
using reliability_test::read_text;
using reliability_test::run;
using reliability_test::scratch;

namespace {

/// A run of `hours` at one sample per `step` s: a heat input (on from 600 s to 60 % of each 6 h
/// cycle when `speed` is set, else one warm-up from 600 s on with a random level), t1..t4 its
/// first-order responses plus a drifting ambient, d1 = 2 µm/K ΔT1 + 1.5 µm/K lp1800(ΔT2), d2 = −1
/// µm/K ΔT3, each with 0.2 µm noise.
io::MeasuredRun synthetic_run(double hours, bool speed, std::uint64_t stream, double step = 120.0) {
  std::mt19937_64 rng = core::generator(11, stream);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> level(0.6, 1.4);
  const auto n = static_cast<Eigen::Index>(hours * 3600.0 / step);
  io::MeasuredRun r;
  r.machine = "synthetic";
  r.run = "shape test " + std::to_string(stream);
  r.sensors = {{"t1", {}}, {"t2", {}}, {"t3", {}}, {"t4", {}}};
  r.displacements = {{"d1", {}, {}}, {"d2", {}, {}}};
  r.time = Eigen::VectorXd::LinSpaced(n, 0.0, step * static_cast<double>(n - 1));
  Eigen::VectorXd heat(n), rpm(n);
  const double a = level(rng);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double in_cycle = std::fmod(r.time(i), 6 * 3600.0);
    const bool on = speed ? in_cycle >= 600.0 && in_cycle < 0.6 * 6 * 3600.0 : r.time(i) >= 600.0;
    rpm(i) = on ? 3000.0 * a : 0.0;
    heat(i) = on ? a : 0.0;
  }
  if (speed) {
    r.inputs = {"speed_rpm"};
    r.input_values = rpm;
  } else {
    r.input_values.resize(n, 0);
  }
  Eigen::VectorXd ambient(n);
  const double phase = 0.7 * static_cast<double>(stream);
  for (Eigen::Index i = 0; i < n; ++i)
    ambient(i) = 20.0 + 0.5 * std::sin(2 * std::numbers::pi * r.time(i) / 86400.0 + phase);
  r.temperature.resize(n, 4);
  const double taus[] = {900.0, 2400.0, 5000.0, 12000.0};
  for (int c = 0; c < 4; ++c)
    r.temperature.col(c) =
        (ambient + (8.0 - c) * fitting::low_pass(r.time, heat, taus[c])).array() +
        core::kCelsiusOffset;
  const Eigen::VectorXd d1 =
      2.0 * (r.temperature.col(0).array() - r.temperature(0, 0)).matrix() +
      1.5 * fitting::low_pass(r.time, (r.temperature.col(1).array() - r.temperature(0, 1)).matrix(),
                              1800.0);
  r.displacement.resize(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    r.displacement(i, 0) = (d1(i) + 0.2 * noise(rng)) * 1e-6;
    r.displacement(i, 1) =
        (-1.0 * (r.temperature(i, 2) - r.temperature(0, 2)) + 0.2 * noise(rng)) * 1e-6;
  }
  return r;
}

fs::path written(const fs::path& dir, const std::string& name, const io::MeasuredRun& r) {
  const fs::path folder = dir / name;
  io::write_measured_run(folder, r);
  return folder;
}

/// Removes the "inputs" key from a written run's meta.json.
void drop_inputs_key(const fs::path& folder) {
  auto meta = nlohmann::json::parse(read_text(folder / "meta.json"));
  meta.erase("inputs");
  std::ofstream(folder / "meta.json") << meta.dump(1);
}

/// fit.json or calibration.json, its folder checked against the command's schemas first.
nlohmann::json json_of(const fs::path& file) {
  EXPECT_TRUE(tt::test::matches_output_schemas(file.filename() == "fit.json" ? "fit" : "calibrate",
                                               file.parent_path()));
  return nlohmann::json::parse(read_text(file));
}

/// Every channel's chosen model beats no compensation on the test groups of a clean run.
void expect_fit_helps(const nlohmann::json& fit) {
  for (const auto& [channel, s] : fit["summary"].items()) {
    SCOPED_TRACE(channel);
    EXPECT_LT(s["test_rms_um"].get<double>(), 0.5 * s["test_rms_uncompensated_um"].get<double>());
    EXPECT_FALSE(s["worse_than_uncompensated_on_test"].get<bool>());
  }
}

}  // namespace

TEST(DataShapes, OneLongRunWithNoInputsKeyIsCutIntoTimeBlocks) {
  const fs::path dir = scratch("shapes_no_inputs_key");
  const fs::path data = written(dir, "run", synthetic_run(60.0, false, 1));
  drop_inputs_key(data);
  ASSERT_EQ(
      run({"fit", "--data", data.string(), "--out", (dir / "fit").string(), "--quiet", "--quick"},
          {}, dir / "fit.log"),
      0)
      << read_text(dir / "fit.log");
  const auto fit = json_of(dir / "fit" / "fit.json");
  EXPECT_NE(fit["blocks"].get<std::string>().find("time blocks"), std::string::npos);
  EXPECT_NE(fit["blocks"].get<std::string>().find("no speed input"), std::string::npos);
  expect_fit_helps(fit);
  ASSERT_EQ(run({"calibrate", "--train", data.string(), "--test", data.string(), "--out",
                 (dir / "cal").string(), "--quiet"},
                {}, dir / "cal.log"),
            0)
      << read_text(dir / "cal.log");
  const auto cal = json_of(dir / "cal" / "calibration.json");
  EXPECT_FALSE(cal["speed_input"].get<bool>());
  EXPECT_FALSE(cal["test_residual_correlations"]["d1"]["after"].contains("speed"));
  EXPECT_EQ(read_text(dir / "cal" / "residual_d1.csv").find("speed"), std::string::npos);
  for (const auto& e : cal["effects"]) EXPECT_NE(e["kind"], "speed_dependent_offset");
}

TEST(DataShapes, EmptyInputsListMeansNoSpeed) {
  const fs::path dir = scratch("shapes_empty_inputs");
  const fs::path data = written(dir, "run", synthetic_run(60.0, false, 2));
  ASSERT_NE(read_text(data / "meta.json").find("\"inputs\": []"), std::string::npos);
  ASSERT_EQ(run({"calibrate", "--train", data.string(), "--test", data.string(), "--out",
                 (dir / "cal").string(), "--quiet"},
                {}, dir / "cal.log"),
            0)
      << read_text(dir / "cal.log");
  const auto cal = json_of(dir / "cal" / "calibration.json");
  EXPECT_FALSE(cal["speed_input"].get<bool>());
  EXPECT_FALSE(cal["test_residual_correlations"]["d2"]["before"].contains("speed"));
  for (const auto& [ch, c] : cal["after"]["channels"].items())
    EXPECT_LE(c["rms_um"].get<double>(), cal["before"]["channels"][ch]["rms_um"].get<double>())
        << ch;
}

TEST(DataShapes, OneRunWithSpeedCycles) {
  const fs::path dir = scratch("shapes_speed_cycles");
  const fs::path data = written(dir, "run", synthetic_run(48.0, true, 3));
  // The full candidate grid, as calibrate uses it (below).
  ASSERT_EQ(run({"fit", "--data", data.string(), "--out", (dir / "fit").string(), "--quiet"}, {},
                dir / "fit.log"),
            0)
      << read_text(dir / "fit.log");
  const auto fit = json_of(dir / "fit" / "fit.json");
  EXPECT_NE(fit["blocks"].get<std::string>().find("speed cycles"), std::string::npos);
  EXPECT_TRUE(fit["summary"]["d1"]["window_mae_continuous_um"].is_number());
  // The held-out data start at rest, at a speed cycle's start (the last stopped sample before the
  // start at 30 h + 600 s here), as training pieces do.
  EXPECT_NE(fit["test_window"]["origin"].get<std::string>().find("speed cycle"), std::string::npos);
  const double from = fit["test_window"]["from_s"].get<double>();
  EXPECT_DOUBLE_EQ(from, 30 * 3600.0 + 480.0);
  const auto written_run = io::read_measured_run(data);
  for (Eigen::Index i = 0; i < written_run.time.size(); ++i)
    if (written_run.time(i) >= from) {
      EXPECT_EQ(written_run.input_values(i, 0), 0.0);
      break;
    }
  // The reference forms are candidates: least squares without the 3 sigma criterion among them.
  bool plain = false;
  for (const auto& c : fit["targets"][0]["candidates"])
    plain = plain || c["model"] == "least_squares(no_3sigma)";
  EXPECT_TRUE(plain);
  for (const auto& [channel, s] : fit["summary"].items()) {
    EXPECT_LE(s["validation_rms_um"].get<double>(),
              s["no_compensation_validation_rms_um"].get<double>())
        << channel;
    EXPECT_GT(s["gain_over_no_compensation_um2"].get<double>(),
              s["gain_over_no_compensation_standard_error_um2"].get<double>())
        << channel;
  }
  expect_fit_helps(fit);
  // calibrate split at the same time starts from the same choice on the same speed cycles and
  // tests it on the same data (the study's terms then include the speed's).
  ASSERT_EQ(run({"calibrate", "--train", data.string(), "--test", data.string(), "--split-s",
                 std::to_string(from), "--out", (dir / "cal").string(), "--quiet"},
                {}, dir / "cal.log"),
            0)
      << read_text(dir / "cal.log");
  const auto cal = json_of(dir / "cal" / "calibration.json");
  EXPECT_TRUE(cal["speed_input"].get<bool>());
  for (const auto& [channel, s] : fit["summary"].items()) {
    SCOPED_TRACE(channel);
    EXPECT_EQ(cal["models"][channel]["baseline_choice"]["model"], s["model"]);
    EXPECT_NEAR(cal["before"]["channels"][channel]["rms_um"].get<double>(),
                s["test_rms_um"].get<double>(), 1e-6 * s["test_rms_um"].get<double>());
  }
}

TEST(DataShapes, ThreeOrMoreRunsTestTheLastWithoutCrashing) {
  const fs::path dir = scratch("shapes_three_runs");
  std::vector<std::string> args{"fit", "--data"};
  for (int k = 0; k < 4; ++k)
    args.push_back(
        written(dir, "run" + std::to_string(k), synthetic_run(10.0, false, 10 + k)).string());
  args.insert(args.end(), {"--out", (dir / "fit").string(), "--quiet"});
  ASSERT_EQ(run(args, {}, dir / "fit.log"), 0) << read_text(dir / "fit.log");
  const auto fit = json_of(dir / "fit" / "fit.json");
  EXPECT_EQ(fit["test_window"]["origin"], "the last run, tested whole");
  EXPECT_TRUE(fit["summary"]["d1"]["window_mae_continuous_um"].is_null());
  expect_fit_helps(fit);
  EXPECT_TRUE(fs::exists(dir / "fit" / "compensation.csv"));
}

TEST(DataShapes, DaysAsRunsWithHeldOutDays) {
  const fs::path dir = scratch("shapes_days");
  std::vector<std::string> train, test;
  for (int k = 0; k < 6; ++k)
    (k < 4 ? train : test)
        .push_back(written(dir, "day" + std::to_string(k + 1), synthetic_run(9.0, false, 20 + k))
                       .string());
  std::vector<std::string> fit_args{"fit", "--data"};
  fit_args.insert(fit_args.end(), train.begin(), train.end());
  fit_args.push_back("--test");
  fit_args.insert(fit_args.end(), test.begin(), test.end());
  // The full candidate grid, as calibrate uses it, so that calibrate's before is this choice.
  fit_args.insert(fit_args.end(), {"--out", (dir / "fit").string(), "--quiet"});
  ASSERT_EQ(run(fit_args, {}, dir / "fit.log"), 0) << read_text(dir / "fit.log");
  const auto fit = json_of(dir / "fit" / "fit.json");
  EXPECT_EQ(fit["groups"].size(), 6u);
  expect_fit_helps(fit);
  std::vector<std::string> cal_args{"calibrate", "--train"};
  cal_args.insert(cal_args.end(), train.begin(), train.end());
  cal_args.push_back("--test");
  cal_args.insert(cal_args.end(), test.begin(), test.end());
  cal_args.insert(cal_args.end(), {"--out", (dir / "cal").string(), "--quiet"});
  ASSERT_EQ(run(cal_args, {}, dir / "cal.log"), 0) << read_text(dir / "cal.log");
  const auto cal = json_of(dir / "cal" / "calibration.json");
  // calibrate's baseline is fit --data's chosen model on the same blocks: the same form and the
  // same test error per channel.
  for (const auto& [channel, s] : fit["summary"].items()) {
    SCOPED_TRACE(channel);
    EXPECT_EQ(cal["models"][channel]["baseline_choice"]["model"], s["model"]);
    EXPECT_EQ(cal["models"][channel]["before"]["form"], s["model"]);
    EXPECT_NEAR(cal["before"]["channels"][channel]["rms_um"].get<double>(),
                s["test_rms_um"].get<double>(), 1e-6 * s["test_rms_um"].get<double>());
    EXPECT_NEAR(cal["models"][channel]["baseline_choice"]["validation_rms_um"].get<double>(),
                s["validation_rms_um"].get<double>(), 1e-6 * s["validation_rms_um"].get<double>());
  }
  for (const auto& [channel, c] : cal["after"]["channels"].items()) {
    if (c["worse_than_before"].get<bool>()) {
      EXPECT_NE(std::find(cal["after_worse_than_before_on_test"].begin(),
                          cal["after_worse_than_before_on_test"].end(), channel),
                cal["after_worse_than_before_on_test"].end());
    }
  }
  for (const auto& e : cal["effects"]) {
    EXPECT_GE(e["null_fraction"].get<double>(), 0.0);
    EXPECT_GT(e["heldout_gain_t"].get<double>(), 2.0);
    EXPECT_LT(e["heldout_training_rms_um_with_it"].get<double>(),
              e["heldout_training_rms_um_before"].get<double>());
  }
}

TEST(DataShapes, RefusalsNameTheCause) {
  const fs::path dir = scratch("shapes_refusals");
  // 16 samples with no speed: too short to cut into 4 time blocks of 10.
  const fs::path tiny = written(dir, "tiny", synthetic_run(16 * 120.0 / 3600.0, false, 30));
  ASSERT_NE(run({"fit", "--data", tiny.string(), "--out", (dir / "fit").string(), "--quick"}, {},
                dir / "fit.log"),
            0);
  const std::string log = read_text(dir / "fit.log");
  EXPECT_NE(log.find("time blocks"), std::string::npos) << log;
  EXPECT_NE(log.find("hint"), std::string::npos) << log;
  EXPECT_NE(log.find("speed column"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir / "fit"));
  // One run with a speed column, one without.
  const fs::path with = written(dir, "with", synthetic_run(12.0, true, 31));
  const fs::path without = written(dir, "without", synthetic_run(12.0, false, 32));
  ASSERT_NE(run({"calibrate", "--train", with.string(), "--test", without.string(), "--out",
                 (dir / "cal").string()},
                {}, dir / "cal.log"),
            0);
  EXPECT_NE(read_text(dir / "cal.log").find("same inputs"), std::string::npos)
      << read_text(dir / "cal.log");
  EXPECT_FALSE(fs::exists(dir / "cal"));
}

TEST(DataShapes, NoCompensationIsChosenWhenNothingBeatsIt) {
  // Error that is noise only: no model beats leaving it alone on held-out blocks.
  io::MeasuredRun r = synthetic_run(40.0, false, 40);
  std::mt19937_64 rng = core::generator(3, 0);
  std::normal_distribution<double> noise(0.0, 1e-6);
  for (Eigen::Index i = 0; i < r.displacement.rows(); ++i) r.displacement(i, 0) = noise(rng);
  const auto blocks = fitting::cross_validation_blocks(io::measured_segments(r, "run"));
  ASSERT_TRUE(blocks.cut_in_time);
  const auto groups = fitting::segment_groups(blocks.segments);
  std::vector<int> pool;
  for (std::size_t i = 0; i < groups.size(); ++i) pool.push_back(static_cast<int>(i));
  fitting::SensorSet all{"all", {0, 1, 2, 3}};
  fitting::ModelSpec none, lagged;
  none.kind = fitting::ModelKind::no_compensation;
  lagged.kind = fitting::ModelKind::distributed_lag;
  lagged.time_constants = {600.0, 3600.0};
  lagged.ridge_lambda = 1e-4;
  const auto e = fitting::blocked_evaluation(
      groups, pool, {}, 0, {{all, none}, {all, fitting::ModelSpec{}}, {all, lagged}});
  EXPECT_EQ(e.model.spec.kind, fitting::ModelKind::no_compensation);
  EXPECT_EQ(e.selection.none, 0);
  if (e.selection.lowest != e.selection.none) {
    EXPECT_LE(e.selection.gain_over_none, e.selection.gain_over_none_standard_error);
  }
  // A channel the temperatures explain gets the model of the lowest held-out mean square, which
  // beats no compensation by more than a standard error.
  const auto cycles = fitting::segment_groups(
      fitting::cross_validation_blocks(io::measured_segments(synthetic_run(48.0, true, 41), "run"))
          .segments);
  std::vector<int> cycle_pool;
  for (std::size_t i = 0; i < cycles.size(); ++i) cycle_pool.push_back(static_cast<int>(i));
  const auto real = fitting::blocked_evaluation(
      cycles, cycle_pool, {}, 0, {{all, none}, {all, fitting::ModelSpec{}}, {all, lagged}});
  EXPECT_NE(real.model.spec.kind, fitting::ModelKind::no_compensation);
  EXPECT_EQ(real.selection.best, real.selection.lowest);
  EXPECT_GT(real.selection.gain_over_none, real.selection.gain_over_none_standard_error);
  for (const auto& c : real.selection.candidates)
    EXPECT_LE(
        fitting::mean_square(
            real.selection.candidates[static_cast<std::size_t>(real.selection.best)].validation),
        fitting::mean_square(c.validation));
}

TEST(DataShapes, ClaimThresholdIsNeverNegative) {
  io::MeasuredRun r = synthetic_run(40.0, false, 50);
  const auto blocks = fitting::cross_validation_blocks(io::measured_segments(r, "run"));
  fitting::ResidualStudyOptions options;
  options.null_draws = 5;
  // From the baseline calibrate takes: fit --data's choice on the same blocks.
  const auto groups = fitting::segment_groups(blocks.segments);
  std::vector<int> pool;
  for (std::size_t i = 0; i < groups.size(); ++i) pool.push_back(static_cast<int>(i));
  const auto choice = fitting::blocked_evaluation(
      groups, pool, {}, 1, fitting::measured_data_candidates(4, false, false));
  const auto study =
      fitting::residual_study(blocks.segments, 1, fitting::baseline_of(choice.model), options);
  for (const auto& step : study.steps)
    for (const auto& e : step)
      if (std::isfinite(e.null_fraction)) {
        EXPECT_GE(e.null_fraction, 0.0);
      }
  for (const auto& e : study.effects) EXPECT_GT(e.gain_t, options.min_gain_t);
}
