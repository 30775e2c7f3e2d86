// The per-kind check shared by the CI and the long variants.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <set>
#include <string>

#include "calibration_fixture.hpp"
#include "core/timing.hpp"
#include "io/calibration_model_out.hpp"
#include "tests/common/calibration_json.hpp"

namespace tt::calibration::testing {

/// What the calibration made of one draw (issue 16's confusion matrix).
struct Outcome {
  std::string first = "none";  /// kind of the first claim
  /// Right first, or nothing claimed and reported ambiguous between a true kind and another.
  bool right = false, ambiguous = false;
  double before = 0, after = 0;  /// test-run RMS against the noise-free truth [um, or K]
  double calibrate_s = 0;        /// wall time of calibrate (choice, refit, test run) [s]
  std::string units;
  CalibrationResult result;
  io::MeasuredRun truth;  /// the test run's noise-free readings
};

/// calibration.json's `effects` of `res`: the claims as written.
inline nlohmann::json claims_json(const CalibrationResult& res) {
  return io::selection_json(res)["effects"];
}

/// Generates the draw `effects` (the first is the one judged for place), calibrates with them
/// undeclared and returns the outcome, printing the ranking, the claims and the figures.
inline Outcome calibrated(const Study& s, const InjectedEffects& effects, std::mt19937_64& rng) {
  std::vector<io::MeasuredRun> noiseless;
  const auto t_gen = std::chrono::steady_clock::now();
  const auto runs = testing::effect_runs(s, effects, rng, &noiseless);
  const double generate_s = core::seconds_since(t_gen);
  const Catalogue cat = testing::with_measured(s.train, {runs[0], runs[1]});
  const auto t0 = std::chrono::steady_clock::now();
  const CalibrationResult res = calibrate(*s.model, s.declared, cat, {runs[2]}, s.copt);
  const double calibrate_s = core::seconds_since(t0);
  std::printf("[calibration] runs generated in %.1f s, calibrated in %.1f s\n", generate_s,
              calibrate_s);
  // RMS against the test run's noise-free truth: no model removes the sensors' noise.
  const io::MeasuredRun& truth = noiseless[2];
  const Eigen::MatrixXd clean = measured_channels(truth, s.train.readout);
  const RmsFigures b = rms_figures({clean}, {res.tests[0].before}, s.train.readout.sensors);
  const RmsFigures a = rms_figures({clean}, {res.tests[0].after}, s.train.readout.sensors);
  bool sensor_kind = true;
  std::set<std::string> kinds;
  for (const auto& e : effects) {
    sensor_kind &= e.kind == EffectKind::sensor_offset || e.kind == EffectKind::sensor_lag;
    kinds.insert(kind_name(e.kind));
  }
  const double before = sensor_kind ? b.temperature_rms_K : 1e6 * b.displacement_rms_m;
  const double after = sensor_kind ? a.temperature_rms_K : 1e6 * a.displacement_rms_m;
  std::printf("[calibration] measured-data RMS: T %.4g -> %.4g K, u %.4g -> %.4g um; null %.1f\n",
              res.before.temperature_rms_K, res.after.temperature_rms_K,
              1e6 * res.before.displacement_rms_m, 1e6 * res.after.displacement_rms_m,
              res.selection.null_score);
  for (size_t k = 0; k < res.selection.ranking.size(); ++k)
    std::printf(
        "[calibration]   rank %zu: %s score %.1f floor %.1f explained %.3f p0 %.4g %s\n", k,
        res.selection.ranking[k].name.c_str(), res.selection.ranking[k].score,
        res.selection.ranking[k].floor, res.selection.ranking[k].explained_fraction,
        res.selection.ranking[k].parameters.empty() ? 0.0 : res.selection.ranking[k].parameters[0],
        res.selection.ranking[k].unphysical.c_str());
  for (const auto& c : res.selection.claimed)
    std::printf("[calibration]   claimed: %s score %.1f floor %.1f p0 %.4g\n", c.name.c_str(),
                c.score, c.floor, c.parameters.empty() ? 0.0 : c.parameters[0]);
  for (const auto& p : res.selection.pairs) {
    std::string gains;
    for (double g : p.fold_gains) gains += " " + std::to_string(g);
    std::printf("[calibration]   pair %s + %s: score %.1f adds %.1f / %.1f%s; per run%s\n",
                p.first.name.c_str(), p.second.name.c_str(), p.score, p.adds_first, p.adds_second,
                p.admissible ? " admissible" : "", gains.c_str());
  }
  if (res.selection.by_pair) std::printf("[calibration]   claimed by the best pair\n");
  for (const auto& [was, now] : res.selection.backfit_replaced)
    std::printf("[calibration]   backfit: %s replaced by %s\n", was.c_str(),
                now.empty() ? "nothing (dropped)" : now.c_str());
  for (const auto& a : res.selection.ambiguous)
    std::printf("[calibration]   ambiguous: %s / %s (difference %.1f, spread %.1f)\n",
                a.first.name.c_str(), a.second.name.c_str(), a.difference, a.spread);
  const nlohmann::json claims = claims_json(res);
  for (const auto& c : claims)
    if (c.contains("refit") && c["refit"].contains("linearised"))
      std::printf("[calibration] refit of %s: linearised %s, refitted %s in %d steps%s; %s\n",
                  c["name"].get<std::string>().c_str(), c["refit"]["linearised"].dump().c_str(),
                  c["refit"]["refitted"].dump().c_str(), c["refit"]["iterations"].get<int>(),
                  c["refit"]["converged"].get<bool>() ? "" : " (cap)",
                  c["refit"].value("heldout_check", nlohmann::json{}).dump().c_str());
  Outcome out;
  out.first = claims.empty() ? "none" : claims[0]["kind"].get<std::string>();
  if (out.first == "sensor_lag")
    std::printf("[calibration] lag found %.4g s\n",
                claims[0]["parameters"]["time_constant_s"].get<double>());
  for (const auto& e : effects)
    std::printf("[calibration] %s magnitude %.4g target '%s'%s%s\n", kind_name(e.kind).c_str(),
                e.magnitude, e.target.c_str(),
                e.kind == EffectKind::speed_dependent_convection
                    ? (" exponent " + std::to_string(e.speed_exponent)).c_str()
                    : "",
                e.kind == EffectKind::heat_input
                    ? (" at (" + std::to_string(e.centre.x()) + ", " +
                       std::to_string(e.centre.y()) + ", " + std::to_string(e.centre.z()) + ") m")
                          .c_str()
                    : "");
  std::printf("[calibration] first %s, RMS before %.4g after %.4g (%s)\n", out.first.c_str(),
              before, after, sensor_kind ? "K" : "um");
  out.right = kinds.count(out.first) > 0;
  for (const auto& a : res.selection.ambiguous)
    out.ambiguous |= claims.empty() && (kinds.count(kind_name(a.first.kind)) > 0 ||
                                        kinds.count(kind_name(a.second.kind)) > 0);
  out.before = before;
  out.after = after;
  out.units = sensor_kind ? "K" : "um";
  out.calibrate_s = calibrate_s;
  out.result = res;
  out.truth = truth;
  return out;
}

/// The declared model's own floor for a draw: the test run simulated by the declared case (its
/// mesh and step) with the truth's effects declared exactly, against the noise-free truth, as a
/// share of the declared case without them (RMS at the TCP, or over the sensors for sensor kinds).
/// No claim of the right kind and size can be expected below it.
inline double floor_ratio(const Study& s, const InjectedEffects& effects,
                          const io::MeasuredRun& truth_run, bool sensor_kind) {
  const Readout& r = s.train.readout;
  core::CaseSpec with = truth_case(s.declared, effects, s.duties[2], 2);
  core::CaseSpec without = truth_case(s.declared, InjectedEffects{}, s.duties[2], 2);
  with.thermal.output_interval = without.thermal.output_interval = s.declared.thermal.step;
  const Eigen::MatrixXd truth = measured_channels(truth_run, r);
  const auto rms = [&](const io::MeasuredRun& run) {
    const RmsFigures f = rms_figures({truth}, {measured_channels(run, r)}, r.sensors);
    return sensor_kind ? f.temperature_rms_K : 1e6 * f.displacement_rms_m;
  };
  const double at = rms(clean_run(s.mesh, with, effects, s.inst, s.gopt, "floor"));
  const double before = rms(clean_run(s.mesh, without, InjectedEffects{}, s.inst, s.gopt, "none"));
  std::printf(
      "[calibration] declared model with the truth's effects: %.4g against %.4g without "
      "(floor after/before %.3f)\n",
      at, before, before > 0 ? at / before : 0.0);
  return before > 0 ? at / before : 0.0;
}

/// One effect kind: generate, calibrate with it undeclared, check kind, place and the test-run RMS
/// after against before.
inline void check_kind(const Study& s, EffectKind kind, std::uint64_t seed) {
  std::mt19937_64 rng = core::generator(seed, static_cast<std::uint64_t>(kind));
  const InjectedEffect e = random_effect(kind, s.declared, s.gen_mesh, s.inst.sensor_points, rng);
  const Outcome out = calibrated(s, {e}, rng);
  const CalibrationResult& res = out.result;
  const nlohmann::json claims = claims_json(res);
  ASSERT_FALSE(claims.empty()) << "no effect claimed";
  EXPECT_EQ(out.first, kind_name(kind)) << claims.dump(1);
  if (kind == EffectKind::heat_input && out.first == "heat_input") {
    const Eigen::Vector3d found = tt::test::effect_centre_m(claims[0]);
    const double err = (found - e.centre).norm();
    std::printf(
        "[calibration] heat input at (%.3f, %.3f, %.3f), found (%.3f, %.3f, %.3f): place error "
        "%.3f m\n",
        e.centre(0), e.centre(1), e.centre(2), found(0), found(1), found(2), err);
    EXPECT_LT(err, 0.1);
  }
  EXPECT_LE(out.after, 0.3 * out.before);
}

/// A draw of the new forms (several places, two effects): the right kind first, or reported
/// ambiguous between a true kind and another; where right, the test-run RMS after at most 0.3 of
/// before.
inline void check_draw(const Study& s, const InjectedEffects& effects, std::mt19937_64& rng) {
  const Outcome out = calibrated(s, effects, rng);
  EXPECT_TRUE(out.right || out.ambiguous) << claims_json(out.result).dump(1);
  if (out.right) {
    EXPECT_LE(out.after, 0.3 * out.before);
  }
}

}  // namespace tt::calibration::testing
