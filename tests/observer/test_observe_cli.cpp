// `thermotwin observe` on the coarse SB-1: a reduced model from `reduce`, a 3-hour run from the
// calibration generator (the case's own mesh and step) with an offset of 0.6 K on one sensor,
// written in the measured-data format. The observer writes its CSV and JSON, raises
// `recalibrate` with its start (offset states off; with the default ones the offset is found as
// the sensor's and explained), and refuses a sensor the model does not name, writing nothing.
// The same run streamed through `compensate --rom` gives the offline observer's predictions, sigmas
// and alarm sample by sample; a stream without the observer's sensor columns is refused.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include "calibration/generator.hpp"
#include "core/rng.hpp"
#include "io/case_reader.hpp"
#include "io/measured_data.hpp"
#include "mesh/mesher.hpp"
#include "tests/common/calibration_json.hpp"
#include "tests/common/csv_rows.hpp"
#include "tests/common/output_schema.hpp"
#include "tests/reliability/process.hpp"

namespace tt::observe_cli_test {
namespace {

namespace fs = std::filesystem;
namespace rt = reliability_test;

/// The coarse SB-1, its mesh, and the calibration generator on that mesh and step (a clean run is
/// the declared model) reading nine sensors.
struct OwnMeshGenerator {
  OwnMeshGenerator() : spec(io::read_case(rt::kCoarseCase)), mesh(mesh::mesh_case(spec)) {
    g.mesh_scale = 1;
    g.step_s = spec.thermal.step;
    gen = calibration::generator_case(spec, g);
    inst.sensor_points = {"T02", "T08", "T11", "T14", "T17", "T25", "T33", "T44", "T52"};
  }
  core::CaseSpec spec;
  mesh::TetMesh mesh;
  calibration::GeneratorOptions g;
  core::CaseSpec gen;
  calibration::Instrumentation inst;
};

/// The coarse SB-1's reduced model (`reduce --quick-validation`), made once for every test here.
const fs::path& coarse_rom() {
  static const fs::path rom = [] {
    const fs::path dir = rt::scratch("observe_rom");
    EXPECT_EQ(rt::run({"reduce", rt::kCoarseCase.string(), "--out", (dir / "rom").string(),
                       "--quick-validation", "--quiet"},
                      {}, dir / "reduce.log"),
              0)
        << rt::read_text(dir / "reduce.log");
    return dir / "rom";
  }();
  return rom;
}

TEST(ObserveCli, OffsetRunRaisesRecalibrateAndBadSensorIsRefused) {
  const fs::path dir = rt::scratch("observe");
  const fs::path& rom = coarse_rom();
  const fs::path data = dir / "run", out = dir / "out";
  // 1. A generated run with a sensor offset.
  const OwnMeshGenerator o;
  const core::CaseSpec& spec = o.spec;
  std::mt19937_64 rng = core::generator(5, 0);
  const calibration::InjectedEffect e{.present = true,
                                      .kind = calibration::EffectKind::sensor_offset,
                                      .magnitude = 0.6,
                                      .target = "T11"};
  const core::DutyCycle duty = calibration::random_duty_cycle(3, rng);
  io::write_measured_run(
      data, calibration::synthetic_run(o.mesh, calibration::truth_case(o.gen, e, duty, 0), e,
                                       o.inst, o.g, "offset", rng));
  // 2. The observer without offset states (the offset is read as heat and alarms).
  const fs::path log = dir / "observe.log";
  const std::vector<std::string> no_offsets{"--sensor-offset-k", "0", "--sensor-offset-walk-k",
                                            "0"};
  std::vector<std::string> observe_args{"observe",
                                        rt::kCoarseCase.string(),
                                        "--rom",
                                        rom.string(),
                                        "--data",
                                        data.string(),
                                        "--out",
                                        out.string(),
                                        "--sensor-sigma-k",
                                        "0.04",
                                        "--quiet"};
  observe_args.insert(observe_args.end(), no_offsets.begin(), no_offsets.end());
  ASSERT_EQ(rt::run(observe_args, {}, log), 0) << rt::read_text(log);
  const std::string csv = rt::read_text(out / "observer.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "time_s,dx_predicted_um,dx_sigma_um,dy_predicted_um,dy_sigma_um,dz_predicted_um,"
            "dz_sigma_um,nis,readings,window_nis,window_bound,status");
  EXPECT_NE(csv.find(",recalibrate\n"), std::string::npos);
  const auto j = nlohmann::json::parse(std::ifstream(out / "observer.json"));
  EXPECT_EQ(j["status"], "recalibrate");
  EXPECT_EQ(j["sensors"].size(), 9u);
  EXPECT_LE(j["recalibrate_since_s"].get<double>(), 900.0);  // the offset is there from t = 0
  EXPECT_LE(j["recalibrate_raised_s"].get<double>(), 3600.0);
  EXPECT_TRUE(j["unknown_inputs"].contains("air"));
  EXPECT_FALSE(j["unknown_inputs"].contains("offset:T11"));
  // Without offset states T11 also reads away from the declared model's run, and is named.
  EXPECT_EQ(j["consistency"]["model_residual_sigmas"], 3.0);
  ASSERT_FALSE(j["model_departures"].empty());
  EXPECT_EQ(j["model_departures"][0]["sensor"], "T11");
  EXPECT_TRUE(tt::test::matches_output_schemas("observe", out));
  // With the default offset states the offset is found as T11's, and explained: no alarm, but
  // the sensor is reported (status sensor_fault, below).
  const fs::path with_offsets = dir / "with_offsets";
  observe_args.resize(observe_args.size() - no_offsets.size());
  observe_args[7] = with_offsets.string();
  ASSERT_EQ(rt::run(observe_args, {}, log), 0) << rt::read_text(log);
  EXPECT_NE(rt::read_text(log).find("warning: sensor T11 reads off by an offset"),
            std::string::npos)
      << rt::read_text(log);
  const auto jo = nlohmann::json::parse(std::ifstream(with_offsets / "observer.json"));
  EXPECT_EQ(jo["noise"]["sensor_offset_K"], 0.5);
  ASSERT_TRUE(jo["unknown_inputs"].contains("offset:T11"));
  // Offsets are in kelvin, heat inputs in watts.
  EXPECT_NEAR(jo.at("unknown_inputs").at("offset:T11").at("final_K").get<double>(), 0.6, 0.1);
  for (const char* other : {"offset:T02", "offset:T17"})
    EXPECT_LT(std::abs(jo.at("unknown_inputs").at(other).at("final_K").get<double>()), 0.1)
        << other;
  // The 0.6 K offset is sure: T11 alone is reported faulty, with its estimate and times.
  EXPECT_EQ(jo["status"], "sensor_fault");
  ASSERT_EQ(jo["sensor_faults"].size(), 1u);
  EXPECT_EQ(jo["sensor_faults"][0]["sensor"], "T11");
  EXPECT_NEAR(jo["sensor_faults"][0]["offset_K"].get<double>(), 0.6, 0.1);
  EXPECT_LE(jo["sensor_faults"][0]["since_s"].get<double>(), 900.0);
  EXPECT_TRUE(tt::test::matches_output_schemas("observe", with_offsets));
  // T11's offset is its own: it is left out of the declared run's test, and nothing else departs.
  EXPECT_TRUE(jo["model_departures"].empty()) << jo["model_departures"].dump();
  EXPECT_TRUE(j["sensor_faults"].empty());  // without offset states no offset test
  // Each material's expansion error widens the drift's sigma and leaves the prediction.
  const fs::path expansion = dir / "expansion";
  std::vector<std::string> expansion_args = observe_args;
  expansion_args[7] = expansion.string();
  expansion_args.insert(expansion_args.end(), {"--expansion-relative-sigma", "0.15"});
  ASSERT_EQ(rt::run(expansion_args, {}, log), 0) << rt::read_text(log);
  const auto je = nlohmann::json::parse(std::ifstream(expansion / "observer.json"));
  ASSERT_EQ(je["noise"]["expansion_relative_sigma"].size(), spec.materials.size());
  for (const auto& m : spec.materials)
    EXPECT_EQ(je["noise"]["expansion_relative_sigma"][m.name], 0.15) << m.name;
  // One value per material, or one for all: two for three materials is refused, naming them,
  // and nothing is written.
  std::vector<std::string> miscounted = expansion_args;
  miscounted[7] = (dir / "miscounted").string();
  miscounted.back() = "0.1,0.2";
  EXPECT_NE(rt::run(miscounted, {}, log), 0);
  EXPECT_NE(rt::read_text(log).find("--expansion-relative-sigma: 2 values for 3 materials"),
            std::string::npos)
      << rt::read_text(log);
  EXPECT_FALSE(fs::exists(dir / "miscounted" / "observer.json"));
  EXPECT_TRUE(tt::test::matches_output_schemas("observe", expansion));
  const auto last_row = [](const fs::path& f) {
    const std::string text = rt::read_text(f);
    const auto end = text.find_last_not_of('\n');
    std::vector<double> v;
    std::stringstream row(text.substr(text.rfind('\n', end) + 1, end - text.rfind('\n', end)));
    for (std::string cell; std::getline(row, cell, ',') && v.size() < 7;)
      v.push_back(std::stod(cell));
    return v;  // time, dx, sigma, dy, sigma, dz, sigma
  };
  const std::vector<double> narrow = last_row(with_offsets / "observer.csv"),
                            wide = last_row(expansion / "observer.csv");
  ASSERT_EQ(narrow.size(), 7u);
  ASSERT_EQ(wide.size(), 7u);
  EXPECT_EQ(wide[5], narrow[5]);                             // dz predicted
  EXPECT_GT(wide[6], narrow[6] + 0.05 * std::abs(wide[5]));  // dz sigma: 0.15 of its parts
  // 3. The recorded run streamed through compensate --rom: the offline observer's figures.
  const io::MeasuredRun measured = io::read_measured_run(data);
  const fs::path live = dir / "live.csv", live_log = dir / "live.log";
  std::vector<std::string> live_args{"compensate",
                                     "--rom",
                                     rom.string(),
                                     "--case",
                                     rt::kCoarseCase.string(),
                                     "--in",
                                     (data / "data.csv").string(),
                                     "--until-eof",
                                     "--out",
                                     live.string(),
                                     "--sensor-sigma-k",
                                     "0.04"};
  if (measured.initial_temperature_c) {
    std::ostringstream t0;
    t0 << std::setprecision(17) << *measured.initial_temperature_c;
    live_args.insert(live_args.end(), {"--initial-temperature-c", t0.str()});
  }
  // The stream through compensate with `flags` against observe's `offline` CSV: the same
  // predictions and sigmas, the same alarm; returns how many samples were alarmed.
  const auto same_as_offline = [&](const fs::path& offline_csv,
                                   const std::vector<std::string>& flags) -> std::size_t {
    std::vector<std::string> args = live_args;
    args.insert(args.end(), flags.begin(), flags.end());
    EXPECT_EQ(rt::run(args, {}, live_log), 0) << rt::read_text(live_log);
    const auto offline = tt::test::csv_rows(offline_csv);
    const auto streamed = tt::test::csv_rows(live);
    EXPECT_EQ(streamed.size(), offline.size());
    if (streamed.size() != offline.size()) return 0;
    double largest = 0, worst = 0;
    std::size_t alarms = 0;
    for (std::size_t i = 0; i < offline.size(); ++i) {
      for (const char* d : {"dx", "dy", "dz"})
        for (const char* what : {"_predicted_um", "_sigma_um"}) {
          const std::string key = std::string(d) + what;
          const double a = std::stod(offline[i].at(key)), b = std::stod(streamed[i].at(key));
          largest = std::max(largest, std::abs(a));
          worst = std::max(worst, std::abs(a - b));
        }
      // The same status: what the observer says (recalibrate, sensor_fault:T11) or ok.
      const std::string& said = offline[i].at("status");
      EXPECT_EQ(streamed[i].at("status"), said) << "sample " << i;
      alarms += said.rfind("recalibrate", 0) == 0;
    }
    EXPECT_GT(largest, 0.5);           // microns of drift were compared
    EXPECT_LE(worst, 1e-7 * largest);  // observer.csv holds 9 digits
    return alarms;
  };
  EXPECT_GT(same_as_offline(out / "observer.csv", no_offsets), 0u);
  // With the default offsets too (no alarm: the offset is explained).
  EXPECT_EQ(same_as_offline(with_offsets / "observer.csv", {}), 0u);
  // A stream without one of the observer's sensors is refused, naming the column.
  const fs::path cut = dir / "cut.csv", cut_log = dir / "cut.log";
  {
    std::ofstream f(cut);
    f << "time_s,speed_rpm,T02\n0,1000,20\n";
  }
  EXPECT_NE(rt::run({"compensate", "--rom", rom.string(), "--case", rt::kCoarseCase.string(),
                     "--in", cut.string(), "--until-eof", "--sensors", "T02,T08"},
                    {}, cut_log),
            0);
  EXPECT_NE(rt::read_text(cut_log).find("header refused: column 'T08' is missing"),
            std::string::npos)
      << rt::read_text(cut_log);
  // A stream on a clock's time (Unix time) is refused at its first sample, naming the file, the
  // line and the time, unless its first sample is taken as t = 0.
  const fs::path clock = dir / "clock.csv";
  {
    std::ofstream f(clock);
    f << "time_s,speed_rpm,T02\n1700000000,1000,20\n1700000060,1000,20.1\n";
  }
  EXPECT_NE(rt::run({"compensate", "--rom", rom.string(), "--case", rt::kCoarseCase.string(),
                     "--in", clock.string(), "--until-eof", "--sensors", "T02"},
                    {}, cut_log),
            0);
  EXPECT_NE(rt::read_text(cut_log).find(clock.string() +
                                        ": line 2: the first sample is at time_s = 1700000000"),
            std::string::npos)
      << rt::read_text(cut_log);
  EXPECT_NE(rt::read_text(cut_log).find("--time-from-first-sample"), std::string::npos);
  const fs::path from_first = dir / "clock_out.csv";
  EXPECT_EQ(rt::run({"compensate", "--rom", rom.string(), "--case", rt::kCoarseCase.string(),
                     "--in", clock.string(), "--until-eof", "--sensors", "T02",
                     "--time-from-first-sample", "--out", from_first.string()},
                    {}, cut_log),
            0)
      << rt::read_text(cut_log);
  const auto clock_rows = tt::test::csv_rows(from_first);
  ASSERT_EQ(clock_rows.size(), 2u);
  EXPECT_EQ(clock_rows[1].at("time_s"), "1700000060");
  EXPECT_EQ(clock_rows[1].at("status"), "ok");
  // 4. A sensor the model does not name: refused, naming it; nothing written.
  const fs::path bad = dir / "bad", bad_log = dir / "bad.log";
  EXPECT_NE(rt::run({"observe", rt::kCoarseCase.string(), "--rom", rom.string(), "--data",
                     data.string(), "--out", bad.string(), "--sensors", "T02,NOPE", "--quiet"},
                    {}, bad_log),
            0);
  EXPECT_NE(rt::read_text(bad_log).find("NOPE"), std::string::npos) << rt::read_text(bad_log);
  EXPECT_FALSE(fs::exists(bad));
  // Sigmas: one for all or one per sensor; two for nine sensors is refused.
  EXPECT_NE(
      rt::run({"observe", rt::kCoarseCase.string(), "--rom", rom.string(), "--data", data.string(),
               "--out", bad.string(), "--sensor-sigma-k", "0.04,0.05", "--quiet"},
              {}, bad_log),
      0);
  EXPECT_NE(rt::read_text(bad_log).find("--sensor-sigma-k: 2 values for 9 sensors"),
            std::string::npos)
      << rt::read_text(bad_log);
  EXPECT_FALSE(fs::exists(bad));
}

TEST(ObserveCli, AlarmThenCalibrateNamesTheEffect) {
  // Issue 20, item 3 end to end: an undeclared 15 W heat input (constant, at a place the
  // generator draws) on the coarse SB-1. `observe` with its default settings reads the run and
  // raises recalibrate, dated; `calibrate --case` on that run and two earlier runs of the same
  // machine then names a heat input near the true place.
  const fs::path dir = rt::scratch("observe_then_calibrate");
  const fs::path& rom = coarse_rom();
  const fs::path observed = dir / "observed", log = dir / "log";
  const OwnMeshGenerator o;
  std::mt19937_64 rng = core::generator(11, 0);
  calibration::InjectedEffect heat = calibration::random_effect(
      calibration::EffectKind::heat_input, o.spec, o.mesh, o.inst.sensor_points, rng);
  heat.magnitude = 15;  // W, within the generator's range (4 .. 25 W)
  heat.follows_speed = false;
  std::vector<std::string> runs;
  const double hours[] = {2, 3, 4};
  for (int k = 0; k < 3; ++k) {
    const core::DutyCycle duty = calibration::random_duty_cycle(hours[k], rng);
    runs.push_back((dir / ("run_" + std::to_string(k))).string());
    io::write_measured_run(runs.back(), calibration::synthetic_run(
                                            o.mesh, calibration::truth_case(o.gen, heat, duty, k),
                                            heat, o.inst, o.g, "heat " + std::to_string(k), rng));
  }
  ASSERT_EQ(rt::run({"observe", rt::kCoarseCase.string(), "--rom", rom.string(), "--data", runs[2],
                     "--out", observed.string(), "--quiet"},
                    {}, log),
            0)
      << rt::read_text(log);
  const auto alarm = nlohmann::json::parse(std::ifstream(observed / "observer.json"));
  std::printf(
      "[observe then calibrate] %.1f W at (%.3f, %.3f, %.3f): status %s, raised at %s s, "
      "since %s s\n",
      heat.magnitude, heat.centre(0), heat.centre(1), heat.centre(2),
      alarm["status"].dump().c_str(), alarm["recalibrate_raised_s"].dump().c_str(),
      alarm["recalibrate_since_s"].dump().c_str());
  ASSERT_EQ(alarm["status"], "recalibrate");
  EXPECT_LT(alarm["recalibrate_raised_s"].get<double>(), 4 * 3600.0);
  // The heat is there from t = 0. Each departing sensor's onset walks back from its crossing of
  // 3 sigma to its last reading within 1 sigma of the declared run, and the alarm is dated from
  // the earliest (180 s here; 540 s from the crossing).
  ASSERT_FALSE(alarm["model_departures"].empty());
  EXPECT_EQ(alarm["consistency"]["departure_onset_sigmas"], 1.0);
  for (const auto& d : alarm["model_departures"]) {
    EXPECT_LE(d["onset_s"].get<double>(), d["since_s"].get<double>()) << d.dump();
    EXPECT_LE(alarm["recalibrate_since_s"].get<double>(), d["onset_s"].get<double>()) << d.dump();
  }
  const fs::path out = dir / "calibrated";
  ASSERT_EQ(rt::run({"calibrate", "--case", rt::kCoarseCase.string(), "--train", runs[0], runs[1],
                     "--test", runs[2], "--out", out.string()},
                    {}, log),
            0)
      << rt::read_text(log);
  const auto j = nlohmann::json::parse(std::ifstream(out / "calibration.json"));
  ASSERT_FALSE(j["effects"].empty()) << j.dump(1);
  const auto& first = j["effects"][0];
  EXPECT_EQ(first["kind"], "heat_input") << j.dump(1);
  const Eigen::Vector3d found = tt::test::effect_centre_m(first);
  std::printf(
      "[observe then calibrate] calibrate: %s at (%.3f, %.3f, %.3f), %s W; u RMS %.3f -> "
      "%.3f um\n",
      first["kind"].dump().c_str(), found(0), found(1), found(2),
      first["parameters"].value("power_W", nlohmann::json()).dump().c_str(),
      j["before"]["displacement_rms_um"].get<double>(),
      j["after"]["displacement_rms_um"].get<double>());
  EXPECT_LT((found - heat.centre).norm(), 0.06);
}

/// RMS of observer.csv's `column` [um] against the run's displacement column of the same target.
double drift_error_rms_um(const fs::path& observed, const io::MeasuredRun& run,
                          const std::string& target) {
  const auto rows = tt::test::csv_rows(observed / "observer.csv");
  const auto p = std::find_if(run.displacements.begin(), run.displacements.end(),
                              [&](const auto& d) { return d.id == target; });
  EXPECT_NE(p, run.displacements.end()) << target;
  EXPECT_EQ(rows.size(), static_cast<std::size_t>(run.time.size()));
  double ss = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double e =
        std::stod(rows[i].at(target + "_predicted_um")) -
        1e6 * run.displacement(static_cast<Eigen::Index>(i), p - run.displacements.begin());
    ss += e * e;
  }
  return std::sqrt(ss / static_cast<double>(rows.size()));
}

TEST(ObserveCli, DriftReadingsSeeAWrongExpansionThatNoTemperatureShows) {
  // A steel whose expansion coefficient is 16 % above the declared one changes no temperature:
  // the observer on temperatures alone cannot see it. With the run's TCP probes read every 30 min
  // (a probe cycle) the filter follows the machine's drift, and with the sigma calibrated as the
  // campaign calibrates it (docs/benchmarks.md: 0.35 dy, 0.15 dz) the readings depart from what
  // the temperatures alone predict on readings in a row and say recalibrate; a clean run read the
  // same way raises nothing.
  const fs::path dir = rt::scratch("observe_drift_readings");
  const fs::path& rom = coarse_rom();
  const OwnMeshGenerator o;
  std::mt19937_64 rng = core::generator(23, 0);
  const calibration::InjectedEffect expansion{.present = true,
                                              .kind = calibration::EffectKind::material_parameter,
                                              .magnitude = 0.16,
                                              .target = "steel.expansion"};
  const calibration::InjectedEffect none;
  const core::DutyCycle duty = calibration::random_duty_cycle(4, rng);
  std::map<std::string, io::MeasuredRun> runs;
  for (const auto& [name, effect] : {std::pair{"expansion", expansion}, std::pair{"clean", none}}) {
    runs[name] = calibration::synthetic_run(o.mesh, calibration::truth_case(o.gen, effect, duty, 0),
                                            effect, o.inst, o.g, name, rng);
    io::write_measured_run(dir / ("run_" + std::string(name)), runs[name]);
  }
  const auto observe = [&](const std::string& run, const std::string& out,
                           std::vector<std::string> extra) {
    std::vector<std::string> args{
        "observe", rt::kCoarseCase.string(),        "--rom", rom.string(),
        "--data",  (dir / ("run_" + run)).string(), "--out", (dir / out).string(),
        "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    EXPECT_EQ(rt::run(args, {}, dir / "log"), 0) << rt::read_text(dir / "log");
    return nlohmann::json::parse(std::ifstream(dir / out / "observer.json"));
  };
  const std::vector<std::string> probe_cycle{"--drift-readings-every-s", "1800",
                                             "--drift-sigma-scale", "0.35,0.35,0.15"};
  const auto blind = observe("expansion", "blind", {});
  const auto probed = observe("expansion", "probed", probe_cycle);
  const auto clean = observe("clean", "clean", probe_cycle);
  const double blind_dz = drift_error_rms_um(dir / "blind", runs["expansion"], "dz");
  const double probed_dz = drift_error_rms_um(dir / "probed", runs["expansion"], "dz");
  std::printf(
      "[drift readings] expansion run: without %s, with %s (raised %s s, departures %s); dz RMS "
      "error %.3f -> %.3f um; clean run with them: %s\n",
      blind["status"].dump().c_str(), probed["status"].dump().c_str(),
      probed["recalibrate_raised_s"].dump().c_str(),
      probed["drift_readings"]["departures"].dump().c_str(), blind_dz, probed_dz,
      clean["status"].dump().c_str());
  EXPECT_NE(blind["status"], "recalibrate");
  EXPECT_FALSE(blind.contains("drift_readings"));
  EXPECT_EQ(probed["status"], "recalibrate");
  const auto& d = probed["drift_readings"];
  EXPECT_EQ(d["every_s"], 1800.0);
  EXPECT_EQ(d["targets"], nlohmann::json({"dx", "dy", "dz"}));
  EXPECT_EQ(d["samples"], 8);  // at 1800, 3600, ..., 14 400 s of a 4-hour run
  ASSERT_FALSE(d["departures"].empty());
  EXPECT_LE(probed["recalibrate_raised_s"].get<double>(), 3 * 3600.0);
  EXPECT_LT(probed_dz, 0.5 * blind_dz);
  EXPECT_EQ(clean["status"], "ok");
  EXPECT_TRUE(clean["drift_readings"]["departures"].empty());
  EXPECT_TRUE(tt::test::matches_output_schemas("observe", dir / "probed"));
  // A factor calibrated with the probe cycle scales the sigma of the filter that reads the probes
  // (here twice the other); the predictions and the drift test (on the temperatures' factor) stay.
  std::vector<std::string> rescaled = probe_cycle;
  rescaled.insert(rescaled.end(), {"--probed-drift-sigma-scale", "0.7,0.7,0.3"});
  const auto twice = observe("expansion", "twice", rescaled);
  EXPECT_EQ(twice["noise"]["probed_drift_sigma_scale"], nlohmann::json({0.7, 0.7, 0.3}));
  EXPECT_EQ(twice["recalibrate_raised_s"], probed["recalibrate_raised_s"]);
  {
    const auto a = tt::test::csv_rows(dir / "probed" / "observer.csv");
    const auto b = tt::test::csv_rows(dir / "twice" / "observer.csv");
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 1; i < a.size(); ++i)
      for (const char* t : {"dx", "dy", "dz"}) {
        const std::string key(t);
        EXPECT_EQ(b[i].at(key + "_predicted_um"), a[i].at(key + "_predicted_um")) << i;
        EXPECT_NEAR(std::stod(b[i].at(key + "_sigma_um")),
                    2 * std::stod(a[i].at(key + "_sigma_um")),
                    1e-7 * (1 + std::stod(b[i].at(key + "_sigma_um"))))
            << i;
      }
  }
  // The same run streamed through `compensate --rom` with the same probe cycle: observe's
  // predictions, sigmas and status, sample by sample.
  std::vector<std::string> live{"compensate",
                                "--rom",
                                rom.string(),
                                "--case",
                                rt::kCoarseCase.string(),
                                "--meta",
                                (dir / "run_expansion" / "meta.json").string(),
                                "--in",
                                (dir / "run_expansion" / "data.csv").string(),
                                "--until-eof",
                                "--out",
                                (dir / "live.csv").string()};
  live.insert(live.end(), probe_cycle.begin(), probe_cycle.end());
  ASSERT_EQ(rt::run(live, {}, dir / "log"), 0) << rt::read_text(dir / "log");
  const auto offline = tt::test::csv_rows(dir / "probed" / "observer.csv");
  const auto streamed = tt::test::csv_rows(dir / "live.csv");
  ASSERT_EQ(streamed.size(), offline.size());
  double worst = 0;
  std::size_t alarmed = 0;
  for (std::size_t i = 0; i < offline.size(); ++i) {
    for (const char* t : {"dx", "dy", "dz"})
      for (const char* what : {"_predicted_um", "_sigma_um"}) {
        const std::string key = std::string(t) + what;
        worst = std::max(worst,
                         std::abs(std::stod(offline[i].at(key)) - std::stod(streamed[i].at(key))));
      }
    EXPECT_EQ(streamed[i].at("status"), offline[i].at("status")) << "sample " << i;
    alarmed += offline[i].at("status") == "recalibrate";
  }
  EXPECT_LE(worst, 1e-6);  // um: observer.csv holds 9 digits
  EXPECT_GT(alarmed, 0u);
  // No displacement column named after a target: refused, nothing written.
  io::MeasuredRun unnamed = runs["clean"];
  for (auto& p : unnamed.displacements) p.id = "probe_" + p.id;
  io::write_measured_run(dir / "unnamed", unnamed);
  EXPECT_NE(rt::run({"observe", rt::kCoarseCase.string(), "--rom", rom.string(), "--data",
                     (dir / "unnamed").string(), "--out", (dir / "refused").string(),
                     "--drift-readings-every-s", "1800"},
                    {}, dir / "log"),
            0);
  EXPECT_NE(rt::read_text(dir / "log").find("no displacement column"), std::string::npos)
      << rt::read_text(dir / "log");
  EXPECT_FALSE(fs::exists(dir / "refused"));
  if (!HasFailure()) fs::remove_all(dir);
}

TEST(ObserveCli, SensorsAreReadAtTheRunsPositions) {
  // The measured-data format locates a sensor by its position, which need not be a mesh vertex
  // or carry a named point's id. A clean 2-hour generated run (sensors at nine named points) is
  // observed as written, then with T17 renamed, then with no positions (by the ids' named
  // points): the same predictions. T17 moved by 30 mm inside the housing is read there (and so
  // predicts otherwise); a position in the air beside the machine is refused, naming the sensor,
  // and nothing is written.
  const fs::path dir = rt::scratch("observe_positions");
  const fs::path& rom = coarse_rom();
  const fs::path log = dir / "log";
  const OwnMeshGenerator o;
  std::mt19937_64 rng = core::generator(17, 0);
  const calibration::InjectedEffect none;
  const io::MeasuredRun clean = calibration::synthetic_run(
      o.mesh, calibration::truth_case(o.gen, none, calibration::random_duty_cycle(2, rng), 0), none,
      o.inst, o.g, "clean", rng);
  const auto observe = [&](const io::MeasuredRun& run, const std::string& name) {
    io::write_measured_run(dir / ("run_" + name), run);
    return rt::run({"observe", rt::kCoarseCase.string(), "--rom", rom.string(), "--data",
                    (dir / ("run_" + name)).string(), "--out", (dir / name).string(), "--quiet"},
                   {}, log);
  };
  const auto places = [&](const std::string& name) {
    return nlohmann::json::parse(std::ifstream(dir / name / "observer.json"))["sensor_places"];
  };
  /// The largest difference of dy and dz's predictions from the run as written [um].
  const auto dy_dz_apart = [&](const std::string& name) {
    const auto a = tt::test::csv_rows(dir / "written" / "observer.csv");
    const auto b = tt::test::csv_rows(dir / name / "observer.csv");
    EXPECT_EQ(a.size(), b.size());
    double most = 0;
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
      for (const char* c : {"dy_predicted_um", "dz_predicted_um"})
        most = std::max(most, std::abs(std::stod(a[i].at(c)) - std::stod(b[i].at(c))));
    return most;
  };
  ASSERT_EQ(observe(clean, "written"), 0) << rt::read_text(log);
  EXPECT_TRUE(tt::test::matches_output_schemas("observe", dir / "written"));
  ASSERT_EQ(places("written").size(), 9u);
  for (const auto& p : places("written")) {
    EXPECT_EQ(p["read_at"], "position") << p;
    EXPECT_LT(p["from_named_point_m"].get<double>(), 1e-12) << p;
  }
  io::MeasuredRun renamed = clean;
  renamed.sensors[4].id = "probe_a";  // T17, where it was
  ASSERT_EQ(observe(renamed, "renamed"), 0) << rt::read_text(log);
  EXPECT_EQ(places("renamed")[4]["sensor"], "probe_a");
  EXPECT_FALSE(places("renamed")[4].contains("from_named_point_m"));
  EXPECT_LT(dy_dz_apart("renamed"), 1e-9);
  io::MeasuredRun unlocated = clean;
  for (auto& s : unlocated.sensors) s.position.reset();
  ASSERT_EQ(observe(unlocated, "unlocated"), 0) << rt::read_text(log);
  for (const auto& p : places("unlocated")) EXPECT_EQ(p["read_at"], "named point") << p;
  EXPECT_LT(dy_dz_apart("unlocated"), 1e-9);
  io::MeasuredRun moved = clean;
  // T17 sits on the housing; 30 mm towards the housing's centre is inside it.
  const Eigen::Vector3d t17 = *clean.sensors[4].position;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : o.mesh.points) centre += p.position;
  centre /= static_cast<double>(o.mesh.points.size());
  moved.sensors[4].position = t17 + 0.03 * (centre - t17).normalized();
  ASSERT_EQ(observe(moved, "moved"), 0) << rt::read_text(log);
  EXPECT_NEAR(places("moved")[4]["from_named_point_m"].get<double>(), 0.03, 1e-9);
  EXPECT_GT(dy_dz_apart("moved"), 1e-4);
  std::printf(
      "[observe positions] T17 read 30 mm off its named point moves dy/dz by up to %.3g um\n",
      dy_dz_apart("moved"));
  io::MeasuredRun outside = clean;  // within the machine's box, below the housing: in the air
  outside.sensors[4].position = Eigen::Vector3d(0.15, 0.29, -0.035);
  EXPECT_NE(observe(outside, "outside"), 0);
  EXPECT_NE(rt::read_text(log).find("sensor 'T17'"), std::string::npos) << rt::read_text(log);
  EXPECT_NE(rt::read_text(log).find("run_outside"), std::string::npos) << rt::read_text(log);
  EXPECT_FALSE(fs::exists(dir / "outside"));
  if (!HasFailure()) fs::remove_all(dir);
}

/// Per target, the nearest-rank `coverage` quantile of |predicted - measured| / (2 sigma) over the
/// samples of observer.csv files (sigma > 0, the drift measured): the factor that puts that share
/// of them within ±2 sigma, worked out here from the written columns. With `mean_window_s`, the
/// measured drift is first averaged over the samples within half of it on either side.
double band_quantile(const std::vector<fs::path>& observed,
                     const std::vector<io::MeasuredRun>& runs, const std::string& target,
                     double coverage, double mean_window_s = 0) {
  std::vector<double> ratio;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const auto rows = tt::test::csv_rows(observed[r] / "observer.csv");
    const auto& d = runs[r].displacements;
    const auto p = std::find_if(d.begin(), d.end(), [&](const auto& x) { return x.id == target; });
    EXPECT_NE(p, d.end()) << target;
    const auto measured = [&](std::size_t i) {
      return 1e6 * runs[r].displacement(static_cast<Eigen::Index>(i), p - d.begin());
    };
    const auto time = [&](std::size_t i) { return std::stod(rows[i].at("time_s")); };
    for (std::size_t i = 0; i < rows.size(); ++i) {
      double mean = 0, n = 0;
      for (std::size_t j = 0; j < rows.size(); ++j)
        if (std::abs(time(j) - time(i)) <= 0.5 * mean_window_s + 1e-9 &&
            std::isfinite(measured(j))) {
          mean += measured(j);
          n += 1;
        }
      const double sigma = std::stod(rows[i].at(target + "_sigma_um"));
      const double e = std::stod(rows[i].at(target + "_predicted_um")) - mean / n;
      if (sigma > 0 && std::isfinite(measured(i))) ratio.push_back(std::abs(e) / (2 * sigma));
    }
  }
  std::sort(ratio.begin(), ratio.end());
  return ratio[static_cast<std::size_t>(std::ceil(coverage * ratio.size() - 1e-9)) - 1];
}

/// Per target, sqrt of the mean of ((predicted - measured)^2 - noise^2) / sigma^2 over the samples
/// of observer.csv files (sigma > 0), or 0 when that mean is not above 0: the NEES rule's factor
/// with the measured drift's noise taken out, worked out here from the written columns [um].
double nees_factor(const std::vector<fs::path>& observed, const std::vector<io::MeasuredRun>& runs,
                   const std::string& target, double noise_um) {
  double sum = 0, n = 0;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const auto rows = tt::test::csv_rows(observed[r] / "observer.csv");
    const auto& d = runs[r].displacements;
    const auto p = std::find_if(d.begin(), d.end(), [&](const auto& x) { return x.id == target; });
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const double sigma = std::stod(rows[i].at(target + "_sigma_um"));
      const double e = std::stod(rows[i].at(target + "_predicted_um")) -
                       1e6 * runs[r].displacement(static_cast<Eigen::Index>(i), p - d.begin());
      if (!(sigma > 0)) continue;
      sum += (e * e - noise_um * noise_um) / (sigma * sigma);
      n += 1;
    }
  }
  return sum > 0 ? std::sqrt(sum / n) : 0.0;
}

/// The share of a run's samples whose measured drift lies within ±2 sigma of observer.csv's.
double band_coverage(const fs::path& observed, const io::MeasuredRun& run,
                     const std::string& target) {
  const auto rows = tt::test::csv_rows(observed / "observer.csv");
  const auto& d = run.displacements;
  const auto p = std::find_if(d.begin(), d.end(), [&](const auto& x) { return x.id == target; });
  double inside = 0, n = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double sigma = std::stod(rows[i].at(target + "_sigma_um"));
    const double e = std::stod(rows[i].at(target + "_predicted_um")) -
                     1e6 * run.displacement(static_cast<Eigen::Index>(i), p - d.begin());
    if (!(sigma > 0)) continue;
    n += 1;
    inside += std::abs(e) <= 2 * sigma;
  }
  return inside / n;
}

using Refusals = std::vector<std::pair<std::vector<std::string>, std::string>>;

/// Each of `refused` (flags, a part of the message) makes `observe` (the flags with --out
/// DIR/refused) exit non-zero with that message in `log`, and writes nothing.
void expect_refused(const std::function<int(std::vector<std::string>)>& observe,
                    const Refusals& refused, const fs::path& dir, const fs::path& log) {
  for (const auto& [flags, message] : refused) {
    std::vector<std::string> args = flags;
    args.insert(args.end(), {"--out", (dir / "refused").string()});
    EXPECT_NE(observe(args), 0) << flags.back();
    EXPECT_NE(rt::read_text(log).find(message), std::string::npos) << rt::read_text(log);
    EXPECT_FALSE(fs::exists(dir / "refused"));
  }
}

/// The run in `run_dir` streamed through `compensate --rom` with the sigma calibration `file`
/// (into DIR/live.csv) gives `observed`'s observer.csv `columns` to 1e-6 um, sample by sample.
/// The open write end of the FIFO `path` once a reader has opened it (waits up to a minute).
int fifo_writer(const fs::path& path) {
  for (int i = 0; i < 6000; ++i) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) {
      ::fcntl(fd, F_SETFL, 0);  // blocking writes
      return fd;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return -1;
}

/// `compensate --rom` with --sigma-calibration `file` on `run_dir`'s run: its sigmas in
/// `columns` are observe's (observer.csv in `observed`). With `remove_file`, the run arrives
/// through a FIFO and `file` is removed once compensate has opened it, before the header: the
/// calibration is read once, at the start, not again when the header binds the model.
void expect_streamed_as_observed(const fs::path& rom, const fs::path& run_dir, const fs::path& file,
                                 const fs::path& observed, const std::vector<std::string>& columns,
                                 const fs::path& dir, const fs::path& log,
                                 bool remove_file = false) {
  const fs::path in = remove_file ? dir / "stream.fifo" : run_dir / "data.csv";
  if (remove_file) ASSERT_EQ(::mkfifo(in.c_str(), 0600), 0);
  const pid_t pid =
      rt::start({"compensate", "--rom", rom.string(), "--case", rt::kCoarseCase.string(), "--meta",
                 (run_dir / "meta.json").string(), "--in", in.string(), "--until-eof", "--out",
                 (dir / "live.csv").string(), "--sigma-calibration", file.string()},
                {}, log);
  if (remove_file) {
    const int fd = fifo_writer(in);
    ASSERT_GE(fd, 0) << rt::read_text(log);
    fs::remove(file);
    const std::string text = rt::read_text(run_dir / "data.csv");
    EXPECT_EQ(::write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
    ::close(fd);
    fs::remove(in);
  }
  ASSERT_EQ(rt::wait_for(pid), 0) << rt::read_text(log);
  const auto offline = tt::test::csv_rows(observed / "observer.csv");
  const auto streamed = tt::test::csv_rows(dir / "live.csv");
  ASSERT_EQ(streamed.size(), offline.size());
  for (std::size_t i = 0; i < offline.size(); ++i)
    for (const std::string& column : columns)
      EXPECT_NEAR(std::stod(streamed[i].at(column)), std::stod(offline[i].at(column)), 1e-6)
          << i << " " << column;
}

TEST(ObserveCli, TheSigmaIsCalibratedOnTrainingRunsWhoseDriftWasMeasured) {
  // Three clean 3-hour runs of the generator with their measured drift: two train the factors on
  // the reported sigma (observe --train), the third is observed with them (--sigma-calibration,
  // and --train with --data in one go). The factors are the 95 % quantile of |error| / 2 sigma
  // that this test works out from the uncalibrated observer.csv; on the held-out run the band
  // then holds near 95 % of the samples. A file calibrated for other sensors, a factor given both
  // ways and a training run without a measured drift are refused, naming what, nothing written.
  const fs::path dir = rt::scratch("observe_sigma_calibration");
  const fs::path& rom = coarse_rom();
  const fs::path log = dir / "log";
  const OwnMeshGenerator o;
  std::mt19937_64 rng = core::generator(29, 0);
  const calibration::InjectedEffect none;
  std::vector<io::MeasuredRun> runs;
  for (const char* name : {"a", "b", "held"}) {
    runs.push_back(calibration::synthetic_run(
        o.mesh, calibration::truth_case(o.gen, none, calibration::random_duty_cycle(3, rng), 0),
        none, o.inst, o.g, name, rng));
    io::write_measured_run(dir / ("run_" + std::string(name)), runs.back());
  }
  const auto observe = [&](std::vector<std::string> extra) {
    std::vector<std::string> args{"observe", rt::kCoarseCase.string(), "--rom", rom.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return rt::run(args, {}, log);
  };
  const std::string run_a = (dir / "run_a").string(), run_b = (dir / "run_b").string(),
                    held = (dir / "run_held").string();
  ASSERT_EQ(observe({"--train", run_a, "--train", run_b, "--out", (dir / "cal").string()}), 0)
      << rt::read_text(log);
  EXPECT_NE(rt::read_text(log).find("sigma calibration: b observed (2 of 2 runs)"),
            std::string::npos)
      << rt::read_text(log);
  EXPECT_TRUE(tt::test::matches_output_schemas("observe", dir / "cal"));
  EXPECT_FALSE(fs::exists(dir / "cal" / "observer.json"));
  const auto cal = nlohmann::json::parse(std::ifstream(dir / "cal" / "sigma_calibration.json"));
  EXPECT_EQ(cal["targets"], nlohmann::json({"dx", "dy", "dz"}));
  EXPECT_EQ(cal["sensors"].size(), 9u);
  EXPECT_EQ(cal["training_runs"], nlohmann::json({"a", "b"}));
  EXPECT_TRUE(cal["probe_cycle"].is_null());
  // The same factors from the uncalibrated observer's own columns.
  for (const auto& r : {std::string("a"), std::string("b"), std::string("held")})
    ASSERT_EQ(observe({"--data", (dir / ("run_" + r)).string(), "--out",
                       (dir / ("plain_" + r)).string(), "--quiet"}),
              0)
        << rt::read_text(log);
  const std::vector<std::string> targets{"dx", "dy", "dz"};
  for (std::size_t t = 0; t < targets.size(); ++t) {
    const double expected =
        band_quantile({dir / "plain_a", dir / "plain_b"}, {runs[0], runs[1]}, targets[t], 0.95);
    EXPECT_NEAR(cal["drift_sigma_scale"][t].get<double>(), expected, 1e-6 * expected) << targets[t];
    EXPECT_GE(cal["temperatures"]["after"][targets[t]]["coverage"].get<double>(), 0.95);
  }
  // The generator's 0.08 um probe noise declared (--truth-sigma-um): the factor is the coverage
  // rule's on the measured drift averaged over 300 s, worked out here too; the NEES rule's with
  // the noise taken out is recorded beside it; a probe cycle gets its own factors, scored between
  // its readings.
  ASSERT_EQ(
      observe({"--train", run_a, "--train", run_b, "--truth-sigma-um", "0.08",
               "--drift-readings-every-s", "1800", "--out", (dir / "noisy").string(), "--quiet"}),
      0)
      << rt::read_text(log);
  EXPECT_TRUE(tt::test::matches_output_schemas("observe", dir / "noisy"));
  const auto noisy = nlohmann::json::parse(std::ifstream(dir / "noisy" / "sigma_calibration.json"));
  EXPECT_EQ(noisy["truth_sigma_um"], 0.08);
  EXPECT_EQ(cal["temperatures"]["rules"], nlohmann::json({"coverage", "coverage", "coverage"}));
  EXPECT_TRUE(cal["temperatures"]["averaged_drift_sigma_scale"].is_null());
  EXPECT_EQ(noisy["temperatures"]["coverage_drift_sigma_scale"], cal["drift_sigma_scale"]);
  for (std::size_t t = 0; t < targets.size(); ++t) {
    const double expected = band_quantile({dir / "plain_a", dir / "plain_b"}, {runs[0], runs[1]},
                                          targets[t], 0.95, 300);
    EXPECT_EQ(noisy["temperatures"]["rules"][t], "averaged") << targets[t];
    EXPECT_NEAR(noisy["drift_sigma_scale"][t].get<double>(), expected, 1e-6 * expected)
        << targets[t];
    EXPECT_EQ(noisy["temperatures"]["averaged_drift_sigma_scale"][t],
              noisy["drift_sigma_scale"][t]);
    // The NEES rule with the noise taken out, recorded (1 where the errors are within the noise).
    const double nees =
        nees_factor({dir / "plain_a", dir / "plain_b"}, {runs[0], runs[1]}, targets[t], 0.08);
    const double nees_expected = nees > 0 ? nees : 1.0;
    EXPECT_NEAR(noisy["temperatures"]["nees_drift_sigma_scale"][t].get<double>(), nees_expected,
                1e-6 * nees_expected)
        << targets[t];
  }
  const auto& probe = noisy["probe_cycle"];
  ASSERT_TRUE(probe.is_object());
  EXPECT_EQ(probe["every_s"], 1800.0);
  EXPECT_EQ(noisy["probed_drift_sigma_scale"], probe["drift_sigma_scale"]);
  // 3 h every 1800 s: six readings per run are left out of its score.
  EXPECT_EQ(probe["after"]["dz"]["samples"].get<int>() + 12,
            noisy["temperatures"]["after"]["dz"]["samples"].get<int>());
  EXPECT_NE(noisy["flags"].get<std::string>().find("--probed-drift-sigma-scale"),
            std::string::npos);
  std::printf(
      "[sigma calibration] factors dx, dy, dz: %s; with the probes' noise declared %s, "
      "with a probe cycle every 1800 s %s\n",
      cal["drift_sigma_scale"].dump().c_str(), noisy["drift_sigma_scale"].dump().c_str(),
      probe["drift_sigma_scale"].dump().c_str());
  // The held-out run with the factors: observe --sigma-calibration, and --train with --data.
  const std::string file = (dir / "cal" / "sigma_calibration.json").string();
  ASSERT_EQ(observe({"--data", held, "--sigma-calibration", file, "--out", (dir / "held").string(),
                     "--quiet"}),
            0)
      << rt::read_text(log);
  ASSERT_EQ(observe({"--train", run_a, "--train", run_b, "--data", held, "--out",
                     (dir / "both").string(), "--quiet"}),
            0)
      << rt::read_text(log);
  EXPECT_EQ(rt::read_text(dir / "both" / "observer.csv"),
            rt::read_text(dir / "held" / "observer.csv"));
  EXPECT_TRUE(tt::test::matches_output_schemas("observe", dir / "both"));
  // compensate --rom takes the same file: the held-out run streamed gives the same sigmas.
  expect_streamed_as_observed(rom, dir / "run_held", file, dir / "held", {"dz_sigma_um"}, dir, log);
  const auto held_json = nlohmann::json::parse(std::ifstream(dir / "held" / "observer.json"));
  EXPECT_EQ(held_json["noise"]["drift_sigma_scale"], cal["drift_sigma_scale"]);
  for (const char* t : {"dy", "dz"}) {
    const double before = band_coverage(dir / "plain_held", runs[2], t);
    const double after = band_coverage(dir / "held", runs[2], t);
    std::printf(
        "[sigma calibration] %s: factor %.3f; held-out run's ±2 sigma coverage %.1f %% -> "
        "%.1f %%\n",
        t, cal["drift_sigma_scale"][t == std::string("dy") ? 1 : 2].get<double>(), 100 * before,
        100 * after);
    EXPECT_GE(after, 0.85) << t;
  }
  // Refused, nothing written: other sensors, the factor given twice, no measured drift.
  expect_refused(
      observe,
      {{{"--data", held, "--sigma-calibration", file, "--sensors", "T02,T08,T11"},
        "calibrated for other sensors"},
       {{"--data", held, "--sigma-calibration", file, "--drift-sigma-scale", "0.5"}, "not both"},
       {{"--data", held, "--sigma-calibration", (dir / "noisy" / "sigma_calibration.json").string(),
         "--drift-readings-every-s", "600"},
        "calibrated with another probe cycle"}},
      dir, log);
  io::MeasuredRun unmeasured = runs[0];
  unmeasured.displacements.clear();
  unmeasured.displacement.resize(unmeasured.time.size(), 0);
  io::write_measured_run(dir / "run_unmeasured", unmeasured);
  EXPECT_NE(observe({"--train", run_a, "--train", (dir / "run_unmeasured").string(), "--out",
                     (dir / "refused").string()}),
            0);
  EXPECT_NE(rt::read_text(log).find("run_unmeasured: a training run of the sigma calibration"),
            std::string::npos)
      << rt::read_text(log);
  EXPECT_FALSE(fs::exists(dir / "refused"));
  if (!HasFailure()) fs::remove_all(dir);
}

TEST(ObserveCli, ChangedRunsChooseTheCorrectionAndExpansionSigma) {
  // Two clean 3-hour runs train the factors; two runs of a changed machine (an undeclared heat
  // input; a material's expansion coefficient 15 % up, which changes no temperature) choose the
  // correction's relative sigma c and the expansion's e (observe --changed). The choice follows
  // the rule written in sigma_calibration.json's grid; a changed run observed with the factors,
  // c and e as flags has the coverage the file gives it (the terms' shortcut is the observer's
  // own sigma); a held-out run with another heat input is covered better than by the clean
  // calibration alone. Refused, nothing written: --changed beside a relative sigma given, the
  // file beside one, a run both trained and changed.
  const fs::path dir = rt::scratch("observe_changed_sigma");
  const fs::path& rom = coarse_rom();
  const fs::path log = dir / "log";
  const OwnMeshGenerator o;
  std::mt19937_64 rng = core::generator(31, 0);
  const calibration::InjectedEffect none;
  calibration::InjectedEffect heat = calibration::random_effect(
      calibration::EffectKind::heat_input, o.spec, o.mesh, o.inst.sensor_points, rng);
  heat.magnitude = 12;
  heat.follows_speed = false;
  calibration::InjectedEffect held_heat = calibration::random_effect(
      calibration::EffectKind::heat_input, o.spec, o.mesh, o.inst.sensor_points, rng);
  held_heat.magnitude = 10;
  held_heat.follows_speed = false;
  const calibration::InjectedEffect expansion{.present = true,
                                              .kind = calibration::EffectKind::material_parameter,
                                              .magnitude = 0.15,
                                              .target = o.spec.materials[0].name + ".expansion"};
  std::map<std::string, io::MeasuredRun> runs;
  int k = 0;
  for (const auto& [name, effect] :
       std::vector<std::pair<std::string, calibration::InjectedEffect>>{{"a", none},
                                                                        {"b", none},
                                                                        {"heat", heat},
                                                                        {"expansion", expansion},
                                                                        {"held", held_heat}}) {
    runs[name] = calibration::synthetic_run(
        o.mesh, calibration::truth_case(o.gen, effect, calibration::random_duty_cycle(3, rng), k++),
        effect, o.inst, o.g, name, rng);
    io::write_measured_run(dir / ("run_" + name), runs[name]);
  }
  const auto path = [&](const std::string& name) { return (dir / ("run_" + name)).string(); };
  const auto observe = [&](std::vector<std::string> extra) {
    std::vector<std::string> args{"observe", rt::kCoarseCase.string(), "--rom", rom.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return rt::run(args, {}, log);
  };
  ASSERT_EQ(observe({"--train", path("a"), "--train", path("b"), "--changed", path("heat"),
                     "--changed", path("expansion"), "--out", (dir / "cal").string()}),
            0)
      << rt::read_text(log);
  EXPECT_NE(rt::read_text(log).find("on the changed runs, correction relative sigma"),
            std::string::npos)
      << rt::read_text(log);
  for (const char* gate : {"gate always (chosen): c", "gate on_evidence: c", "gate after_alarm: c"})
    EXPECT_NE(rt::read_text(log).find(gate), std::string::npos) << rt::read_text(log);
  EXPECT_TRUE(tt::test::matches_output_schemas("observe", dir / "cal"));
  const auto cal = nlohmann::json::parse(std::ifstream(dir / "cal" / "sigma_calibration.json"));
  const auto& ch = cal["changed_machine"];
  ASSERT_TRUE(ch.is_object());
  EXPECT_EQ(ch["runs"], nlohmann::json({"heat", "expansion"}));
  ASSERT_EQ(ch["grid"].size(), 36u);  // the reduced model keeps its drift rows per material
  // The rule, worked out here from the grid: the narrowest pair that covers 95 % in every target
  // within reach (one that the widest pair, the last, covers), and within a point of the widest
  // pair's coverage in the others.
  const auto& grid = ch["grid"];
  std::optional<std::size_t> best;
  std::vector<std::string> out_of_reach;
  for (const char* t : {"dx", "dy", "dz"})
    if (grid.back()["score"][t]["coverage"].get<double>() < 0.95) out_of_reach.push_back(t);
  EXPECT_EQ(ch["out_of_reach"], nlohmann::json(out_of_reach));
  for (std::size_t i = 0; i < grid.size(); ++i) {
    bool reaches = true;
    for (const char* t : {"dx", "dy", "dz"}) {
      const double covered = grid[i]["score"][t]["coverage"].get<double>();
      if (std::find(out_of_reach.begin(), out_of_reach.end(), t) == out_of_reach.end())
        reaches = reaches && covered >= 0.95;
      else
        reaches = reaches && covered >= grid.back()["score"][t]["coverage"].get<double>() - 0.01;
      if (i > 0)  // the sigma grows with c and e: so does the coverage
        EXPECT_GE(covered, grid[i % 6 == 0 ? i - 6 : i - 1]["score"][t]["coverage"].get<double>())
            << i << " " << t;
    }
    EXPECT_EQ(grid[i]["reaches_goal"].get<bool>(), reaches) << i;
    if (reaches && (!best || grid[i]["width"] < grid[*best]["width"])) best = i;
  }
  ASSERT_TRUE(best.has_value());
  const double c = ch["correction_relative_sigma"], e = ch["expansion_relative_sigma"];
  EXPECT_EQ(grid[*best]["correction_relative_sigma"], c);
  EXPECT_EQ(grid[*best]["expansion_relative_sigma"], e);
  EXPECT_EQ(cal["correction_relative_sigma"], c);
  EXPECT_GT(c + e, 0.0);  // the clean factors alone do not cover a changed machine
  EXPECT_NE(cal["flags"].get<std::string>().find("--correction-relative-sigma"), std::string::npos);
  // Every gate's choice from the same observation: the file's gate (always) is the pair chosen;
  // after the alarm the clean training runs (no alarm) keep the factors' own band, always on it
  // is wider.
  const auto& gates = ch["gates"];
  ASSERT_EQ(gates.size(), 3u);
  const auto gate_pair = [](const nlohmann::json& g) {
    return std::make_pair(g["correction_relative_sigma"].get<double>(),
                          g["expansion_relative_sigma"].get<double>());
  };
  EXPECT_EQ(gates[0]["gate"], "always");
  EXPECT_EQ(gate_pair(gates[0]), std::make_pair(c, e));
  EXPECT_EQ(gates[2]["gate"], "after_alarm");
  for (const char* t : {"dx", "dy", "dz"}) {
    const double factors_alone = cal["temperatures"]["after"][t]["rms_sigma_um"];
    EXPECT_NEAR(gates[2]["training"][t]["rms_sigma_um"].get<double>(), factors_alone,
                1e-9 * factors_alone)
        << t;
    EXPECT_GE(gates[0]["training"][t]["rms_sigma_um"].get<double>(), factors_alone) << t;
  }
  // Terms on evidence under every evidence setting: the observer's own (300 s, onset 1 sigma) is
  // the gate's; the chosen one reaches its goal with the narrowest training band of those that do.
  const auto& settings = ch["evidence_settings"];
  ASSERT_EQ(settings.size(), 25u);
  int own = 0, chosen = 0;
  double narrowest = std::numeric_limits<double>::infinity(), chosen_width = 0;
  nlohmann::json data_setting;
  for (const auto& s : settings) {
    if (s["evidence_time_s"] == 300.0 && s["onset_sigmas"] == 1.0) {
      ++own;
      EXPECT_EQ(gate_pair(s), gate_pair(gates[1]));
      EXPECT_NEAR(s["training_width"].get<double>(), gates[1]["training_width"].get<double>(),
                  1e-9);
    }
    EXPECT_EQ(s["bound_sigmas"], 3.0);
    if (s["reaches_goal"].get<bool>())
      narrowest = std::min(narrowest, s["training_width"].get<double>());
    if (s["chosen"].get<bool>()) {
      ++chosen;
      chosen_width = s["training_width"];
      data_setting = s;
    }
  }
  EXPECT_EQ(own, 1);
  ASSERT_EQ(chosen, 1);
  ASSERT_TRUE(std::isfinite(narrowest));  // here some setting reaches every goal
  EXPECT_EQ(chosen_width, narrowest);
  // The changed runs observed with the file's factors, c and e as flags: their coverage is the
  // file's (per_run after), to a sample.
  std::ostringstream factors, flag_c, flag_e;
  factors << cal["drift_sigma_scale"][0].get<double>() << ","
          << cal["drift_sigma_scale"][1].get<double>() << ","
          << cal["drift_sigma_scale"][2].get<double>();
  flag_c << c;
  flag_e << e;
  for (std::size_t r = 0; r < 2; ++r) {
    const std::string name = ch["runs"][r];
    ASSERT_EQ(observe({"--data", path(name), "--drift-sigma-scale", factors.str(),
                       "--correction-relative-sigma", flag_c.str(), "--expansion-relative-sigma",
                       flag_e.str(), "--out", (dir / ("flags_" + name)).string(), "--quiet"}),
              0)
        << rt::read_text(log);
    for (const char* t : {"dx", "dy", "dz"}) {
      const auto& after = ch["per_run"][r]["after"][t];
      EXPECT_NEAR(band_coverage(dir / ("flags_" + name), runs[name], t),
                  after["coverage"].get<double>(), 1.5 / after["samples"].get<double>())
          << name << " " << t;
    }
  }
  // The held-out heat run: the file (factors, c, e) against the clean runs' factors alone.
  ASSERT_EQ(observe({"--train", path("a"), "--train", path("b"), "--out",
                     (dir / "clean_cal").string(), "--quiet"}),
            0)
      << rt::read_text(log);
  for (const char* which : {"cal", "clean_cal"})
    ASSERT_EQ(observe({"--data", path("held"), "--sigma-calibration",
                       (dir / which / "sigma_calibration.json").string(), "--out",
                       (dir / ("held_" + std::string(which))).string(), "--quiet"}),
              0)
        << rt::read_text(log);
  const auto held = nlohmann::json::parse(std::ifstream(dir / "held_cal" / "observer.json"));
  EXPECT_EQ(held["noise"]["correction_relative_sigma"], c);
  for (const char* t : {"dy", "dz"}) {
    const double before = band_coverage(dir / "held_clean_cal", runs["held"], t);
    const double after = band_coverage(dir / "held_cal", runs["held"], t);
    std::printf(
        "[changed sigma] c %.2f, e %.2f (out of reach: %s): held-out %.0f W heat run's %s "
        "coverage %.1f %% with the clean factors alone, %.1f %% with c and e\n",
        c, e, ch["out_of_reach"].dump().c_str(), held_heat.magnitude, t, 100 * before, 100 * after);
    EXPECT_GE(after, before) << t;
  }
  // The terms after the alarm (--changed-terms-after-alarm): chosen and applied so.
  ASSERT_EQ(observe({"--train", path("a"), "--train", path("b"), "--changed", path("heat"),
                     "--changed", path("expansion"), "--changed-terms-after-alarm", "--data",
                     path("held"), "--out", (dir / "gated").string()}),
            0)
      << rt::read_text(log);
  // A wrong expansion coefficient changes no temperature: no alarm, so nothing to score there.
  EXPECT_NE(rt::read_text(log).find("changed run expansion raised no alarm"), std::string::npos)
      << rt::read_text(log);
  const auto gated = nlohmann::json::parse(std::ifstream(dir / "gated" / "sigma_calibration.json"));
  EXPECT_EQ(gated["changed_machine"]["after_alarm"], true);
  EXPECT_EQ(gated["changed_machine"]["gate"], "after_alarm");
  // The pair chosen with the gate is the one the run without it reported for that gate.
  EXPECT_EQ(gate_pair(gated), gate_pair(gates[2]));
  EXPECT_NE(gated["flags"].get<std::string>().find("--changed-terms-after-alarm"),
            std::string::npos);
  const auto gated_held = nlohmann::json::parse(std::ifstream(dir / "gated" / "observer.json"));
  EXPECT_EQ(gated_held["noise"]["changed_terms_after_alarm"], true);
  EXPECT_EQ(gated_held["noise"]["changed_terms"], "after_alarm");
  // compensate --rom takes the same file: the held-out run streamed gives observe's sigmas, the
  // terms switched on at the same alarm.
  expect_streamed_as_observed(rom, dir / "run_held", dir / "gated" / "sigma_calibration.json",
                              dir / "gated", {"dy_sigma_um", "dz_sigma_um"}, dir, log);
  std::printf("[changed sigma] after the alarm: c %.2f, e %.2f; held-out run raised at %s s\n",
              gated["correction_relative_sigma"].get<double>(),
              gated["expansion_relative_sigma"].get<double>(),
              gated_held["recalibrate_raised_s"].dump().c_str());
  // The terms on evidence (--changed-terms-on-evidence): chosen and applied so; on the held-out
  // heat run they cover at least what the clean runs' factors alone do. With --choose-evidence
  // the pair is the one of the setting the changed runs chose, and the file carries that setting
  // to the runs observed with it; without, the options' (the gate's in `gates`, at the default
  // 300 s and 1 sigma).
  ASSERT_EQ(observe({"--train", path("a"), "--train", path("b"), "--changed", path("heat"),
                     "--changed", path("expansion"), "--changed-terms-on-evidence",
                     "--choose-evidence", "--out", (dir / "evidence").string(), "--quiet"}),
            0)
      << rt::read_text(log);
  const fs::path evidence_file = dir / "evidence" / "sigma_calibration.json";
  const auto evidence = nlohmann::json::parse(std::ifstream(evidence_file));
  EXPECT_EQ(evidence["changed_machine"]["gate"], "on_evidence");
  EXPECT_EQ(evidence["changed_machine"]["after_alarm"], false);
  EXPECT_EQ(gate_pair(evidence), gate_pair(data_setting));
  const auto& chosen_with = evidence["changed_machine"]["consistency"];
  EXPECT_EQ(chosen_with["evidence_time_s"], data_setting["evidence_time_s"]);
  EXPECT_EQ(chosen_with["evidence_onset_sigmas"], data_setting["onset_sigmas"]);
  EXPECT_NE(evidence["flags"].get<std::string>().find("--changed-terms-on-evidence"),
            std::string::npos);
  EXPECT_NE(evidence["flags"].get<std::string>().find("--evidence-onset-sigmas"),
            std::string::npos);
  ASSERT_EQ(observe({"--train", path("a"), "--train", path("b"), "--changed", path("heat"),
                     "--changed", path("expansion"), "--changed-terms-on-evidence", "--out",
                     (dir / "evidence300").string(), "--quiet"}),
            0)
      << rt::read_text(log);
  const fs::path evidence300_file = dir / "evidence300" / "sigma_calibration.json";
  const auto evidence300 = nlohmann::json::parse(std::ifstream(evidence300_file));
  EXPECT_EQ(gate_pair(evidence300), gate_pair(gates[1]));
  EXPECT_EQ(evidence300["changed_machine"]["consistency"]["evidence_time_s"], 300.0);
  EXPECT_EQ(evidence300["changed_machine"]["consistency"]["evidence_onset_sigmas"], 1.0);
  ASSERT_EQ(observe({"--data", path("held"), "--sigma-calibration", evidence_file.string(), "--out",
                     (dir / "held_evidence").string(), "--quiet"}),
            0)
      << rt::read_text(log);
  const auto evidence_held =
      nlohmann::json::parse(std::ifstream(dir / "held_evidence" / "observer.json"));
  EXPECT_EQ(evidence_held["noise"]["changed_terms"], "on_evidence");
  EXPECT_EQ(evidence_held["consistency"]["evidence_time_s"], data_setting["evidence_time_s"]);
  EXPECT_EQ(evidence_held["consistency"]["evidence_onset_sigmas"], data_setting["onset_sigmas"]);
  std::printf("[changed sigma] on evidence, the changed runs' setting: %s s, onset %s sigma\n",
              data_setting["evidence_time_s"].dump().c_str(),
              data_setting["onset_sigmas"].dump().c_str());
  expect_streamed_as_observed(rom, dir / "run_held", evidence_file, dir / "held_evidence",
                              {"dy_sigma_um", "dz_sigma_um"}, dir, log);
  // The file read once, at the start: removed while compensate waits for the stream's header, it
  // still gives the same sigmas (a copy, which the others below do not need).
  fs::copy_file(evidence_file, dir / "once.json");
  expect_streamed_as_observed(rom, dir / "run_held", dir / "once.json", dir / "held_evidence",
                              {"dy_sigma_um", "dz_sigma_um"}, dir, log, true);
  EXPECT_FALSE(fs::exists(dir / "once.json"));
  ASSERT_EQ(observe({"--data", path("held"), "--sigma-calibration", evidence300_file.string(),
                     "--out", (dir / "held_evidence300").string(), "--quiet"}),
            0)
      << rt::read_text(log);
  for (const char* t : {"dy", "dz"}) {
    const double before = band_coverage(dir / "held_clean_cal", runs["held"], t);
    const double after = band_coverage(dir / "held_evidence", runs["held"], t);
    const double after300 = band_coverage(dir / "held_evidence300", runs["held"], t);
    std::printf(
        "[changed sigma] on evidence: c %.2f, e %.2f; held-out run's %s coverage %.1f %% (at 300 "
        "s and 1 sigma: c %.2f, e %.2f, %.1f %%)\n",
        evidence["correction_relative_sigma"].get<double>(),
        evidence["expansion_relative_sigma"].get<double>(), t, 100 * after,
        evidence300["correction_relative_sigma"].get<double>(),
        evidence300["expansion_relative_sigma"].get<double>(), 100 * after300);
    EXPECT_GE(after, before) << t;
    EXPECT_GE(after300, before) << t;
  }
  // A file of session 18 (after_alarm, no gate) is read as it was written: the gate after the
  // alarm. A gate not known, or one that disagrees with after_alarm, is refused.
  const auto with_gate = [&](const char* name, const nlohmann::json& gate, bool after_alarm) {
    nlohmann::json j = gated;
    j["changed_machine"]["after_alarm"] = after_alarm;
    if (gate.is_null())
      j["changed_machine"].erase("gate");
    else
      j["changed_machine"]["gate"] = gate;
    std::ofstream(dir / name) << j.dump();
    return (dir / name).string();
  };
  ASSERT_EQ(
      observe({"--data", path("held"), "--sigma-calibration", with_gate("old.json", nullptr, true),
               "--out", (dir / "old").string(), "--quiet"}),
      0)
      << rt::read_text(log);
  EXPECT_EQ(
      nlohmann::json::parse(std::ifstream(dir / "old" / "observer.json"))["noise"]["changed_terms"],
      "after_alarm");
  // Refused, nothing written.
  const std::string file = (dir / "cal" / "sigma_calibration.json").string();
  expect_refused(
      observe,
      {{{"--train", path("a"), "--changed", path("heat"), "--correction-relative-sigma", "1"},
        "give it or them, not both"},
       {{"--data", path("held"), "--sigma-calibration", file, "--expansion-relative-sigma", "0.1"},
        "its changed_machine chose"},
       {{"--data", path("held"), "--sigma-calibration", file, "--changed-terms-after-alarm"},
        "changed_machine.gate = \"always\""},
       {{"--data", path("held"), "--sigma-calibration", evidence_file.string(),
         "--changed-terms-after-alarm"},
        "changed_machine.gate = \"on_evidence\""},
       {{"--data", path("held"), "--changed-terms-after-alarm", "--changed-terms-on-evidence"},
        "excludes"},
       {{"--data", path("held"), "--sigma-calibration", evidence300_file.string(),
         "--evidence-time-s", "0"},
        "changed_machine.consistency.evidence_time_s = 300.0: its gated relative sigmas were "
        "chosen with that setting, not --evidence-time-s 0.0"},
       {{"--data", path("held"), "--sigma-calibration", evidence300_file.string(),
         "--evidence-onset-sigmas", "2"},
        "changed_machine.consistency.evidence_onset_sigmas = 1.0"},
       {{"--data", path("held"), "--sigma-calibration",
         (dir / "gated" / "sigma_calibration.json").string(), "--sustain-s", "600"},
        "changed_machine.consistency.sustain_s = 900.0"},
       {{"--data", path("held"), "--sigma-calibration", with_gate("bad.json", "sometimes", false)},
        "changed_machine.gate = \"sometimes\": expected"},
       {{"--data", path("held"), "--sigma-calibration", with_gate("odd.json", "on_evidence", true)},
        "disagrees with changed_machine.gate"},
       {{"--train", path("a"), "--changed", path("a")}, "--changed"},
       {{"--data", path("held"), "--changed", path("heat")}, "--changed requires --train"},
       {{"--train", path("a"), "--changed", path("heat"), "--choose-evidence"},
        "--choose-evidence chooses the evidence of --changed-terms-on-evidence"},
       {{"--train", path("a"), "--changed", path("heat"), "--changed-terms-on-evidence",
         "--choose-evidence", "--evidence-time-s", "60"},
        "give it or them, not both"},
       {{"--data", path("held"), "--choose-evidence"}, "--choose-evidence requires --changed"},
       {{"--train", path("a"), "--changed", path("heat"), "--changed-terms-on-evidence",
         "--choose-evidence", "--model-residual-sigmas", "0"},
        "--model-residual-sigmas 0 turns that test off"}},
      dir, log);
  if (!HasFailure()) fs::remove_all(dir);
}

TEST(ObserveCli, ObserverSettingsAreFlagsAndABadValueIsRefused) {
  // The observer's settings are flags of `observe` and `compensate --rom`, in their --help; a
  // value that makes no sense is refused before any file is read, naming the flag and the value,
  // and nothing is written.
  const fs::path dir = rt::scratch("observe_flags"), out = dir / "out", log = dir / "flags.log";
  for (const char* command : {"observe", "compensate"}) {
    ASSERT_EQ(rt::run({command, "--help"}, {}, log), 0) << rt::read_text(log);
    const std::string help = rt::read_text(log);
    for (const char* flag :
         {"--sensor-offset-k", "--sensor-offset-walk-k", "--widen-on-inconsistency",
          "--heat-initial-w", "--air-initial-k", "--state-walk-k", "--drift-sigma-scale",
          "--sensor-fault-sigmas", "--correction-relative-sigma", "--expansion-relative-sigma",
          "--model-residual-sigmas", "--drift-readings-every-s", "--drift-reading-sigma-um",
          "--sigma-calibration", "--changed-terms-after-alarm", "--changed-terms-on-evidence",
          "--evidence-time-s", "--evidence-onset-sigmas"})
      EXPECT_NE(help.find(flag), std::string::npos) << command << " --help lacks " << flag;
  }
  const std::vector<std::string> base{
      "observe",   rt::kCoarseCase.string(), "--rom", dir.string(), "--data", dir.string(), "--out",
      out.string()};
  const std::vector<std::pair<std::vector<std::string>, std::string>> bad{
      {{"--sensor-offset-k", "-0.5"}, "--sensor-offset-k: -0.5: expected a finite number >= 0"},
      {{"--evidence-time-s", "-1"}, "--evidence-time-s: -1: expected a finite number >= 0"},
      {{"--evidence-onset-sigmas", "nan"},
       "--evidence-onset-sigmas: nan: expected a finite number >= 0"},
      {{"--sensor-offset-walk-k", "nan"},
       "--sensor-offset-walk-k: nan: expected a finite number >= 0"},
      {{"--heat-walk-w", "inf"}, "--heat-walk-w: inf: expected a finite number >= 0"},
      {{"--sensor-fault-sigmas", "-1"}, "--sensor-fault-sigmas: -1: expected a finite number >= 0"},
      {{"--model-residual-sigmas", "nan"},
       "--model-residual-sigmas: nan: expected a finite number >= 0"},
      {{"--expansion-relative-sigma", "-0.1"},
       "--expansion-relative-sigma: -0.1: expected a finite number >= 0"},
      {{"--widen-on-inconsistency=maybe"}, "--widen-on-inconsistency"}};
  for (const auto& [flags, message] : bad) {
    std::vector<std::string> args = base;
    args.insert(args.end(), flags.begin(), flags.end());
    EXPECT_NE(rt::run(args, {}, log), 0) << flags.front();
    EXPECT_NE(rt::read_text(log).find(message), std::string::npos)
        << flags.front() << ": " << rt::read_text(log);
    EXPECT_FALSE(fs::exists(out));
  }
}

}  // namespace
}  // namespace tt::observe_cli_test
