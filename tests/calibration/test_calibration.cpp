// Calibration against generated runs with undeclared effects (CI scale: coarse meshes, 2-hour
// runs). For each effect kind: the right kind comes first, a heat input is placed within 0.1 m,
// and the test-run RMS after is at most 30 % of before; on clean runs at most 1 in 10 is given an
// effect; the air is read from a run's ambient sensor, and heat loss following the speed on every
// film is not claimed as air. Plus small unit checks of the pieces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "calibration_checks.hpp"
#include "core/errors.hpp"
#include "io/calibration_model_out.hpp"

namespace tt::calibration {
namespace {

using testing::check_kind;
using testing::Scale;
using testing::Study;

Study& study() {
  static std::unique_ptr<Study> s = testing::make_study(Scale{});
  return *s;
}

TEST(Lag, ExactForARampAfterTheTransient) {
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(201, 0, 2000), x = 0.01 * t;
  const Eigen::VectorXd y = lagged(t, x, 100);
  // y = 0.01 (t - tau (1 - exp(-t / tau))) for x = 0.01 t, y(0) = 0.
  for (Eigen::Index k = 0; k < t.size(); ++k)
    EXPECT_NEAR(y(k), 0.01 * (t(k) - 100 * (1 - std::exp(-t(k) / 100))), 1e-12);
}

// A lag between two grid values is found by the refinement: the grid alone would leave most of the
// signal of a 269 s lag to the 300 s candidate.
TEST(Lag, RefinedBetweenGridValues) {
  Catalogue cat;
  cat.readout.ids = {"T1"};
  cat.readout.sensors = 1;
  CalibrationOptions o;
  for (int k = 0; k < 2; ++k) {
    RunModel rm;
    rm.name = "run " + std::to_string(k);
    rm.times = Eigen::VectorXd::LinSpaced(241, 0, 14400);
    rm.base.resize(rm.times.size(), 1);
    for (Eigen::Index i = 0; i < rm.times.size(); ++i)  // warm-up with steps and a slow wave
      rm.base(i, 0) = 293 + 3 * (1 - std::exp(-rm.times(i) / 2000)) +
                      ((static_cast<int>(rm.times(i) / (900 + 600 * k)) % 2) ? 0.8 : 0.0) +
                      0.5 * std::sin(rm.times(i) / 1500);
    rm.measured = rm.base;
    rm.measured.col(0) = lagged(rm.times, rm.base.col(0), 269);
    std::mt19937_64 rng = core::generator(5, static_cast<std::uint64_t>(k));
    std::normal_distribution<double> noise(0, 0.01);
    for (Eigen::Index i = 0; i < rm.times.size(); ++i) rm.measured(i, 0) += noise(rng);
    cat.runs.push_back(rm);
  }
  const Catalogue grid = with_refined_lag(cat, 0, 300, [] {
    CalibrationOptions none;
    none.lag_refine_steps = 1;
    return none;
  }());
  const Catalogue fine = with_refined_lag(cat, 0, 300, o);
  EXPECT_EQ(grid.candidates.size(), 0u);
  // Every step but the one at the grid value itself (300 s is the geometric middle of 200, 450).
  ASSERT_EQ(fine.candidates.size(), static_cast<size_t>(o.lag_refine_steps - 2));
  const Selection sel = select_effects(fine, o);
  ASSERT_FALSE(sel.claimed.empty());
  const double tau =
      std::get<SensorLag>(fine.candidates[static_cast<size_t>(sel.claimed[0].candidate)].effect)
          .time_constant_s;
  EXPECT_NEAR(tau, 269, 0.05 * 269);
}

TEST(CaseForRun, SpeedColumnBecomesSegments) {
  io::MeasuredRun run;
  run.run = "r";
  run.inputs = {"speed_rpm"};
  run.time = Eigen::VectorXd::LinSpaced(6, 0, 500);
  run.input_values = (Eigen::MatrixXd(6, 1) << 3000, 3000, 0, 0, 1500, 1500).finished();
  const core::CaseSpec s = case_for_run(study().declared, run);
  ASSERT_EQ(s.duty_cycle.segments.size(), 3u);
  EXPECT_DOUBLE_EQ(s.duty_cycle.segments[1].start, 200);
  EXPECT_DOUBLE_EQ(s.duty_cycle.segments[2].speed_rpm, 1500);
  EXPECT_DOUBLE_EQ(s.duty_cycle.end, 500);
  run.inputs = {"feed"};
  EXPECT_THROW(case_for_run(study().declared, run), core::DataError);
}

TEST(Readout, WeightsArePartitionsOfUnity) {
  const auto w = point_weights(study().mesh, Eigen::Vector3d(0.01, 0.2, 0.3));
  double sum = 0;
  for (const auto& [node, x] : w) sum += x;
  EXPECT_NEAR(sum, 1.0, 1e-12);
}

TEST(Augment, HeatInputCaseReadsBackAndMeshesWithTheNewGroup) {
  const Study& s = study();
  const Candidate* patch = nullptr;
  for (const auto& c : s.train.candidates)
    if (const auto* h = std::get_if<HeatInput>(&c.effect);
        h && h->groups.size() == 1 && s.declared.groups.at(h->groups[0]).name == "housing_outer") {
      patch = &c;
      break;
    }
  ASSERT_NE(patch, nullptr);
  const AugmentedCase a = augmented_case({s.declared, {}, {}}, *patch, {100.0}, s.train.readout);
  const core::CaseSpec again = io::case_from_toml(io::resolved_case_toml(a.spec), "augmented.toml");
  ASSERT_EQ(again.groups.size(), s.declared.groups.size() + 1);
  const mesh::TetMesh m = mesh::mesh_case(again);
  const auto rep = mesh::mesh_report(m, again);
  int g = -1;
  for (size_t k = 0; k < again.groups.size(); ++k)
    if (again.groups[k].name.rfind("heat_input_", 0) == 0) g = static_cast<int>(k);
  ASSERT_GE(g, 0);
  // The new group holds exactly the patch's faces (same mesh: groups do not change TetGen's input).
  EXPECT_NEAR(rep.group_areas[g], std::get<HeatInput>(patch->effect).area, 1e-9);
  EXPECT_EQ(m.nodes.rows(), s.mesh.nodes.rows());
}

// One machine serves a draw's runs (their duty cycles and air differ, nothing else): each run reads
// as if simulated on its own, and a truth with another material is refused.
TEST(TruthMachine, SharedByADrawsRunsGivesEachRunsOwnReadings) {
  const Study& s = study();
  std::mt19937_64 rng = core::generator(77, 0);
  const InjectedEffect e =
      random_effect(EffectKind::heat_input, s.declared, s.mesh, s.inst.sensor_points, rng);
  const core::DutyCycle first = random_duty_cycle(0.5, rng), second = random_duty_cycle(0.5, rng);
  const TruthMachine machine = truth_machine(s.mesh, truth_case(s.declared, e, first, 0), s.inst);
  EXPECT_NE(machine.mesh.group_names, s.mesh.group_names);  // the heat input's group added
  const core::CaseSpec truth = truth_case(s.declared, e, second, 1);
  const io::MeasuredRun shared = clean_run(machine, truth, {e}, s.gopt, "shared");
  const io::MeasuredRun own = clean_run(s.mesh, truth, e, s.inst, s.gopt, "own");
  ASSERT_EQ(shared.temperature.rows(), own.temperature.rows());
  EXPECT_EQ(shared.temperature, own.temperature);
  ASSERT_EQ(shared.displacement.cols(), 3);
  EXPECT_LE((shared.displacement - own.displacement).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_GT(own.displacement.cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_TRUE(serves(machine, truth));
  // Without the heat input's group, or with another material: another machine's truth.
  EXPECT_FALSE(serves(machine, truth_case(s.declared, InjectedEffect{}, second, 1)));
  core::CaseSpec other = truth;
  other.materials.front().expansion *= 1.1;
  EXPECT_FALSE(serves(machine, other));
  EXPECT_THROW(clean_run(machine, other, {e}, s.gopt, "other"), std::invalid_argument);
}

TEST(Kinds, AmbientTemperature) {
  check_kind(study(), EffectKind::ambient_temperature, 11);
}
// The draw is 4.7 W, near the bottom of the range: it moves the tool by about 0.1 um.
TEST(Kinds, HeatInput) {
  check_kind(study(), EffectKind::heat_input, 12);
}
// The drawn gain moves the tool by about 0.08 um; the truth's speed exponent is 0.8, the
// calibrator's 1.
TEST(Kinds, SpeedDependentConvection) {
  check_kind(study(), EffectKind::speed_dependent_convection, 13);
}
TEST(Kinds, TemperatureDependentHeat) {
  check_kind(study(), EffectKind::temperature_dependent_heat, 14);
}
TEST(Kinds, BoundaryConductance) {
  check_kind(study(), EffectKind::boundary_conductance, 15);
}
TEST(Kinds, MaterialParameter) {
  check_kind(study(), EffectKind::material_parameter, 16);
}
TEST(Kinds, SensorOffset) {
  check_kind(study(), EffectKind::sensor_offset, 17);
}
// One lagged sensor of 16, judged on the RMS over all of them: the lag (269 s, between two grid
// values) must be found closely enough that the lagged channel falls below the others' error.
TEST(Kinds, SensorLag) {
  check_kind(study(), EffectKind::sensor_lag, 18);
}

/// Training and test runs of the generator's truth with every unfixed film growing with speed
/// (h x 2 at 3000 rpm, exponent 0.8): a mechanism acting on the same sinks as the air, which no
/// single-film candidate matches.
std::vector<io::MeasuredRun> speed_on_every_film(const Study& s, const Instrumentation& inst,
                                                 std::vector<io::MeasuredRun>* clean) {
  std::mt19937_64 rng = core::generator(21, 1);
  std::vector<io::MeasuredRun> out;
  // The films' speed gain changes no elastic input: one machine for the three runs.
  const TruthMachine machine =
      truth_machine(s.gen_mesh, truth_case(s.gen, InjectedEffect{}, s.duties[0], 0), inst);
  for (int k = 0; k < 3; ++k) {
    core::CaseSpec t = truth_case(s.gen, InjectedEffect{}, s.duties[k], k);
    const auto& fixed = t.mechanical.fixed_groups;
    for (auto& c : t.thermal.convection)
      if (std::find(fixed.begin(), fixed.end(), c.group) == fixed.end()) {
        c.h_speed_gain = 2 * c.h;
        c.speed_ref_rpm = 3000;
        c.speed_exponent = 0.8;
      }
    io::MeasuredRun c =
        clean_run(machine, t, {}, s.gopt, (k < 2 ? "train " : "test ") + std::to_string(k));
    out.push_back(with_noise(c, s.gopt, rng));
    if (clean) clean->push_back(std::move(c));
  }
  return out;
}

// Issue 16: a free per-run air explained away heat loss that follows the speed (6-hour training
// runs). At this scale the speed mechanism comes first on this set even with the air's rules off
// (with them, the bounded air on the unfixed sinks scores 73 069 against 75 329 for the air gap's
// film alone, 77 174 for every unfixed film by one share of its h, the truth's form, which is
// claimed); what the rules add here is the report: the air on every sink follows the duty cycle
// (|r| = 0.76) and says so (ninth of the twelve runners-up).
TEST(Air, SpeedOnEveryFilmIsNotTakenForAir) {
  const Study& s = study();
  std::vector<io::MeasuredRun> clean;
  const auto runs = speed_on_every_film(s, s.inst, &clean);
  const Catalogue cat = testing::with_measured(s.train, {runs[0], runs[1]});
  const CalibrationResult res = calibrate(*s.model, s.declared, cat, {runs[2]}, s.copt);
  const nlohmann::json written = io::selection_json(res);  // calibration.json's account
  for (const auto& f : res.selection.ranking)
    std::printf("[calibration]   %s score %.1f duty correlation %.3f %s\n", f.name.c_str(), f.score,
                f.duty_correlation, f.unphysical.c_str());
  const Eigen::MatrixXd truth = measured_channels(clean[2], s.train.readout);
  const RmsFigures b = rms_figures({truth}, {res.tests[0].before}, s.train.readout.sensors);
  const RmsFigures a = rms_figures({truth}, {res.tests[0].after}, s.train.readout.sensors);
  std::printf("[calibration] claimed %s; test RMS u %.4g -> %.4g um\n",
              written["effects"].empty() ? "none"
                                         : written["effects"][0]["name"].get<std::string>().c_str(),
              1e6 * b.displacement_rms_m, 1e6 * a.displacement_rms_m);
  for (const auto& e : written["effects"]) EXPECT_NE(e["kind"], "ambient_temperature");
  bool air_reported = false;
  for (const auto& e : written["runners_up"])
    air_reported |= e["kind"] == "ambient_temperature" && e.contains("unphysical");
  EXPECT_TRUE(air_reported) << written["runners_up"].dump(1);
  ASSERT_FALSE(written["effects"].empty()) << io::selection_json(res).dump(1);
  EXPECT_EQ(written["effects"][0]["kind"], "speed_dependent_convection");
}

// With an ambient sensor the air is read: a changing shop air is claimed from the sensor (no
// parameters fitted), and the speed mechanism's set keeps its air at the declared 20 degC.
TEST(Air, ReadFromTheRunsAmbientSensor) {
  const Study& s = study();
  Instrumentation inst = s.inst;
  inst.ambient_sensor = true;
  std::mt19937_64 rng =
      core::generator(11, static_cast<std::uint64_t>(EffectKind::ambient_temperature));
  const InjectedEffect e = random_effect(EffectKind::ambient_temperature, s.declared, s.gen_mesh,
                                         inst.sensor_points, rng);
  std::vector<io::MeasuredRun> runs, clean;
  const TruthMachine machine =
      truth_machine(s.gen_mesh, truth_case(s.gen, e, s.duties[0], 0), inst);
  for (int k = 0; k < 3; ++k) {
    const core::CaseSpec t = truth_case(s.gen, e, s.duties[k], k);
    clean.push_back(clean_run(machine, t, {e}, s.gopt, "run " + std::to_string(k)));
    runs.push_back(with_noise(clean.back(), s.gopt, rng));
  }
  const Catalogue cat = testing::with_measured(s.train, {runs[0], runs[1]});
  Catalogue with_air = cat;
  for (size_t k = 0; k < 2; ++k) with_air.runs[k].air = ambient_reading(runs[k]);
  ASSERT_EQ(with_air.runs[0].air.size(), with_air.runs[0].times.size());
  const CalibrationResult res = calibrate(*s.model, s.declared, with_air, {runs[2]}, s.copt);
  const nlohmann::json written = io::selection_json(res);  // calibration.json's account
  ASSERT_FALSE(written["effects"].empty());
  EXPECT_EQ(written["effects"][0]["kind"], "ambient_temperature");
  for (const auto& run : written["effects"][0]["parameters"]["per_training_run"])
    EXPECT_EQ(run["air"], "ambient sensor");
  const Eigen::MatrixXd truth = measured_channels(clean[2], s.train.readout);
  const RmsFigures b = rms_figures({truth}, {res.tests[0].before}, s.train.readout.sensors);
  const RmsFigures a = rms_figures({truth}, {res.tests[0].after}, s.train.readout.sensors);
  std::printf("[calibration] air read from the sensor: test RMS u %.4g -> %.4g um\n",
              1e6 * b.displacement_rms_m, 1e6 * a.displacement_rms_m);
  EXPECT_LE(a.displacement_rms_m, 0.3 * b.displacement_rms_m);
}

// Issue 16 item 2: heat that grows with temperature feeds back on itself, so its response is
// not linear in the coefficient, and the fit linearised about the declared model's cooler
// bearings overstates it. A coefficient of 0.07 /K on the front bearing (within the generator's
// 0.02-0.08 range) is fitted visibly off by the linearisation; the refit about the updated model
// must find it within 10 %: the declared model's own error against the generator's finer truth
// (0.0023 K over the sensors) and the noise leave a few per cent (measured: docs/calibration.md,
// "Refit").
TEST(Refit, HeatGrowingWithTemperatureIsSizedNotItsShadow) {
  const Study& s = study();
  const InjectedEffect e{.present = true,
                         .kind = EffectKind::temperature_dependent_heat,
                         .magnitude = 0.07,
                         .target = "front_bearing_friction"};
  std::mt19937_64 rng = core::generator(31, 1);
  std::vector<io::MeasuredRun> clean;
  const auto runs = testing::effect_runs(s, {e}, rng, &clean);
  const Catalogue cat = testing::with_measured(s.train, {runs[0], runs[1]});
  const CalibrationResult res = calibrate(*s.model, s.declared, cat, {runs[2]}, s.copt);
  const nlohmann::json written = io::selection_json(res);  // calibration.json's account
  ASSERT_FALSE(written["effects"].empty()) << io::selection_json(res).dump(1);
  const nlohmann::json& claim = written["effects"][0];
  ASSERT_EQ(claim["kind"], "temperature_dependent_heat") << claim.dump(1);
  EXPECT_EQ(claim["location"]["source"], "front_bearing_friction");
  ASSERT_TRUE(claim.contains("refit")) << claim.dump(1);
  const double linearised =
      claim["refit"]["linearised"]["temperature_coefficient_per_K"].get<double>();
  const double refitted = claim["refit"]["refitted"]["temperature_coefficient_per_K"].get<double>();
  const Eigen::MatrixXd truth = measured_channels(clean[2], s.train.readout);
  const RmsFigures b = rms_figures({truth}, {res.tests[0].before}, s.train.readout.sensors);
  const RmsFigures a = rms_figures({truth}, {res.tests[0].after}, s.train.readout.sensors);
  std::printf(
      "[calibration] refit: true %.4g /K, linearised %.4g (%+.1f %%), refitted %.4g (%+.1f %%) in "
      "%d steps (%s); whitened SS %.1f -> %.1f; test RMS u %.4g -> %.4g um, T %.4g -> %.4g K\n",
      e.magnitude, linearised, 100 * (linearised / e.magnitude - 1), refitted,
      100 * (refitted / e.magnitude - 1), claim["refit"]["iterations"].get<int>(),
      claim["refit"]["converged"].get<bool>() ? "converged" : "cap",
      claim["refit"]["whitened_ss_at_linearised"].get<double>(),
      claim["refit"]["whitened_ss_at_refitted"].get<double>(), 1e6 * b.displacement_rms_m,
      1e6 * a.displacement_rms_m, b.temperature_rms_K, a.temperature_rms_K);
  // The draw must show the linearisation's error, or the test shows nothing.
  EXPECT_GT(std::abs(linearised / e.magnitude - 1), 0.10);
  EXPECT_NEAR(refitted, e.magnitude, 0.10 * e.magnitude);
  EXPECT_TRUE(claim["refit"]["converged"].get<bool>());
  EXPECT_LT(claim["refit"]["whitened_ss_at_refitted"].get<double>(),
            claim["refit"]["whitened_ss_at_linearised"].get<double>());
  EXPECT_LE(a.displacement_rms_m, 0.3 * b.displacement_rms_m);
}

// Issue 16 item 3: two undeclared effects at once, the shaft's outer film doubled and the front
// bearing's heat growing by 4 %/K, both not linear in their parameter: both kinds claimed (scored
// jointly among the first round's best, or one after the other), both sized by the refit about the
// model updated with the other. (A random heat-input draw is not used here: its box is drawn on the
// generator's mesh, whose faces move with the build's floating point.)
// Disabled from 1bfa644 until 2026-11-26 (only the heat law claimed, or with the bearing's
// conductivity +25 % in place of the film): each pool member's partners were found on what its own
// fit alone left, where the heat law had taken part of the film's signal. Partners are now found by
// fitting each candidate jointly with the member (docs/calibration.md, "Pairs scored jointly").
TEST(Pairs, TwoEffectsAreClaimedTogether) {
  const Study& s = study();
  std::mt19937_64 rng = core::generator(41, 1);
  const InjectedEffect film{.present = true,
                            .kind = EffectKind::boundary_conductance,
                            .magnitude = 1.0,
                            .target = "shaft_outside"};
  const InjectedEffect heat{.present = true,
                            .kind = EffectKind::temperature_dependent_heat,
                            .magnitude = 0.04,
                            .target = "front_bearing_friction"};
  std::vector<io::MeasuredRun> runs, clean;
  const TruthMachine machine = truth_machine(
      s.gen_mesh, truth_case(truth_case(s.gen, film, s.duties[0], 0), heat, s.duties[0], 0),
      s.inst);
  for (int k = 0; k < 3; ++k) {
    const core::CaseSpec t =
        truth_case(truth_case(s.gen, film, s.duties[k], k), heat, s.duties[k], k);
    clean.push_back(
        clean_run(machine, t, {}, s.gopt, (k < 2 ? "train " : "test ") + std::to_string(k)));
    runs.push_back(with_noise(clean.back(), s.gopt, rng));
  }
  const Catalogue cat = testing::with_measured(s.train, {runs[0], runs[1]});
  const CalibrationResult res = calibrate(*s.model, s.declared, cat, {runs[2]}, s.copt);
  const nlohmann::json written = io::selection_json(res);  // calibration.json's account
  const Eigen::MatrixXd truth = measured_channels(clean[2], s.train.readout);
  const RmsFigures b = rms_figures({truth}, {res.tests[0].before}, s.train.readout.sensors);
  const RmsFigures a = rms_figures({truth}, {res.tests[0].after}, s.train.readout.sensors);
  std::printf("[calibration] two effects: %s %+.3g on %s, %s %.3g /K on %s\n",
              kind_name(film.kind).c_str(), film.magnitude, film.target.c_str(),
              kind_name(heat.kind).c_str(), heat.magnitude, heat.target.c_str());
  for (const auto& f : res.selection.ranking)
    std::printf("[calibration]   rank %s: score %.1f p %.4g (linearised %.4g) %s\n", f.name.c_str(),
                f.score, f.parameters.empty() ? 0.0 : f.parameters[0],
                f.linearised.empty() ? 0.0 : f.linearised[0], f.unphysical.c_str());
  for (const auto& p : res.selection.pairs)
    std::printf("[calibration]   pair %s + %s: score %.1f adds %.1f / %.1f %s\n",
                p.first.name.c_str(), p.second.name.c_str(), p.score, p.adds_first, p.adds_second,
                p.admissible ? "admissible" : "");
  for (const auto& e : written["effects"])
    std::printf("[calibration]   claimed %s: %s, refit %s\n", e["name"].get<std::string>().c_str(),
                e["parameters"].dump().c_str(), e.value("refit", nlohmann::json{}).dump().c_str());
  std::printf("[calibration] by pair: %s; test RMS u %.4g -> %.4g um, T %.4g -> %.4g K\n",
              res.selection.by_pair ? "yes" : "no (greedy)", 1e6 * b.displacement_rms_m,
              1e6 * a.displacement_rms_m, b.temperature_rms_K, a.temperature_rms_K);
  ASSERT_EQ(written["effects"].size(), 2u) << io::selection_json(res).dump(1);
  std::set<std::string> kinds{written["effects"][0]["kind"], written["effects"][1]["kind"]};
  EXPECT_EQ(kinds, (std::set<std::string>{"boundary_conductance", "temperature_dependent_heat"}));
  EXPECT_FALSE(res.selection.pairs.empty());
  EXPECT_LE(a.displacement_rms_m, 0.3 * b.displacement_rms_m);
}

TEST(Clean, AtMostOneInTenGetsAnEffect) {
  const Study& s = study();
  std::vector<io::MeasuredRun> clean;
  const TruthMachine machine =
      truth_machine(s.gen_mesh, truth_case(s.gen, InjectedEffect{}, s.duties[0], 0), s.inst);
  for (int k = 0; k < 2; ++k)
    clean.push_back(clean_run(machine, truth_case(s.gen, InjectedEffect{}, s.duties[k], k), {},
                              s.gopt, "clean " + std::to_string(k)));
  int claimed = 0;
  const int trials = 10;
  for (int t = 0; t < trials; ++t) {
    std::mt19937_64 rng = core::generator(99, static_cast<std::uint64_t>(t));
    const Catalogue cat = testing::with_measured(
        s.train, {with_noise(clean[0], s.gopt, rng), with_noise(clean[1], s.gopt, rng)});
    const Selection sel = select_effects(cat, s.copt);
    if (!sel.claimed.empty()) {
      ++claimed;
      std::printf("[calibration] clean draw %d: claimed %s (score %.1f, null %.1f, floor %.1f)\n",
                  t, sel.claimed[0].name.c_str(), sel.claimed[0].score, sel.null_score,
                  sel.claimed[0].floor);
    }
  }
  std::printf("[calibration] clean runs given an effect: %d of %d\n", claimed, trials);
  EXPECT_LE(claimed, trials / 10);
}

}  // namespace
}  // namespace tt::calibration
