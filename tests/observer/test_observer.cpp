// The physics observer on the coarse SB-1 twin (cases/sb1_coarse.toml), against runs made by the
// calibration generator on the case's own mesh and step (so that a clean run is the declared
// model up to the reduction's 1e-4 K): the filter without noise reproduces the reduced model; on
// a clean noisy run the true TCP drift lies within ±2σ near 95 % of the time; the innovation test
// raises `recalibrate` on a run with an undeclared heat input and stays quiet on a clean run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <random>

#include "calibration/generator.hpp"
#include "calibration/model.hpp"
#include "core/errors.hpp"
#include "core/rng.hpp"
#include "core/units.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/loads.hpp"
#include "solvers/observer.hpp"
#include "solvers/observer_live.hpp"
#include "solvers/twin.hpp"
#include "studies/catalogue_detection.hpp"
#include "studies/estimation_input.hpp"
#include "studies/observer_sigma.hpp"

namespace tt::observer_test {
namespace {

const std::vector<std::string> kSensors{"T02", "T08", "T11", "T14", "T17",
                                        "T25", "T33", "T44", "T52"};

struct Study {
  core::CaseSpec spec;
  mesh::TetMesh mesh;
  solvers::Twin twin;
  core::DutyCycle duty;
  /// The generator on the case's own mesh and step (a clean run is the declared model), reading
  /// kSensors.
  calibration::GeneratorOptions g;
  core::CaseSpec gen;
  calibration::Instrumentation inst;
  io::MeasuredRun clean_truth;  /// a generated run without effect, without noise
  io::MeasuredRun clean, heat;  /// noisy generated runs: no effect, an undeclared heat input
};

/// A 4-hour duty cycle of the generator's kind (segments at 0 .. 4000 rpm).
core::DutyCycle duty_cycle(std::uint64_t seed) {
  std::mt19937_64 rng = core::generator(seed, 0);
  return calibration::random_duty_cycle(4.0, rng);
}

class Observer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    s_ = new Study;
    s_->spec = io::read_case(std::string(TT_SOURCE_DIR) + "/cases/sb1_coarse.toml");
    s_->mesh = mesh::mesh_case(s_->spec);
    s_->twin = solvers::case_twin(s_->mesh, s_->spec);
    s_->duty = duty_cycle(7);
    calibration::GeneratorOptions& g = s_->g;
    g.mesh_scale = 1;
    g.step_s = s_->spec.thermal.step;
    s_->gen = calibration::generator_case(s_->spec, g);
    const core::CaseSpec& gen = s_->gen;
    calibration::Instrumentation& inst = s_->inst;
    inst.sensor_points = kSensors;
    std::mt19937_64 rng = core::generator(11, 0);
    const calibration::InjectedEffect none;
    s_->clean_truth = calibration::clean_run(
        s_->mesh, calibration::truth_case(gen, none, s_->duty, 0), none, inst, g, "clean");
    s_->clean = calibration::with_noise(s_->clean_truth, g, rng);
    calibration::InjectedEffect heat = calibration::random_effect(
        calibration::EffectKind::heat_input, s_->spec, s_->mesh, kSensors, rng);
    heat.magnitude = 15;  // W, constant from t = 0: within the generator's range (4 .. 25 W)
    heat.follows_speed = false;
    s_->heat = calibration::synthetic_run(s_->mesh, calibration::truth_case(gen, heat, s_->duty, 1),
                                          heat, inst, g, "heat", rng);
  }
  static void TearDownTestSuite() { delete s_; }

  static core::CaseSpec run_spec() {
    core::CaseSpec c = s_->spec;
    c.duty_cycle = s_->duty;
    return c;
  }
  static solvers::ObserverSetup setup(const solvers::ObserverNoise& noise) {
    return solvers::twin_observer_setup(s_->twin, s_->spec, kSensors, noise);
  }
  static solvers::ObserverNoise default_noise() {
    solvers::ObserverNoise n;
    // The generator's sensors: 0.03 K white, 0.01 K drifting, 0.01 K steps.
    n.sensor_sigma_k = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(kSensors.size()), 0.04);
    return n;
  }
  /// Per candidate of `names` (named points), the held change of its reading [sigmas of 0.04 K]
  /// between two twin runs, `c` and `c` with the sinks of `entries` 1 K warmer: over every four
  /// consecutive outputs after t = 0, the largest of the smallest |change| (900 s of readings
  /// every 300 s); and the number of output times.
  static std::pair<std::vector<double>, std::size_t> held_air_change(
      const core::CaseSpec& c, const std::vector<int>& entries,
      const std::vector<std::string>& names) {
    core::CaseSpec warmer = c;
    for (int k : entries)
      for (double& v : warmer.thermal.convection[static_cast<std::size_t>(k)].sink.value) v += 1;
    const solvers::TwinRun declared = solvers::twin_run(s_->twin, c);
    const solvers::TwinRun changed = solvers::twin_run(s_->twin, warmer);
    const auto times = static_cast<Eigen::Index>(declared.times.size());
    std::vector<double> out;
    for (const auto& name : names) {
      const int col = solvers::temperature_row(s_->twin.outputs, name);
      const Eigen::VectorXd change =
          (changed.outputs.col(col) - declared.outputs.col(col)).tail(times - 1).cwiseAbs() / 0.04;
      double held = 0;
      for (Eigen::Index i = 0; i + 4 <= change.size(); ++i)
        held = std::max(held, change.segment(i, 4).minCoeff());
      out.push_back(held);
    }
    return {out, declared.times.size()};
  }
  /// The clean run's true drift as the observer's targets: the TCP's known, the rest NaN.
  static Eigen::MatrixXd clean_tcp_truth(const solvers::ObserverRun& run) {
    Eigen::MatrixXd truth = Eigen::MatrixXd::Constant(run.drift.rows(), run.drift.cols(),
                                                      std::numeric_limits<double>::quiet_NaN());
    truth.leftCols(3) = s_->clean_truth.displacement.leftCols(3);
    return truth;
  }
  static Study* s_;
};
Study* Observer::s_ = nullptr;

TEST_F(Observer, WithoutNoiseItIsTheReducedModel) {
  // No process noise and a sure start: the gain is zero and the filter is the twin's run, under
  // either scheme (Crank–Nicolson's transition (C + dt/2 A)^-1 (C - dt/2 A) and its restarts).
  solvers::ObserverNoise n = default_noise();
  n.heat_walk_w = n.heat_initial_w = n.air_walk_k = n.air_initial_k = 0;
  for (const auto scheme : {core::TimeScheme::backward_euler, core::TimeScheme::crank_nicolson}) {
    core::CaseSpec c = run_spec();
    c.thermal.scheme = scheme;
    const solvers::TwinRun twin = solvers::twin_run(s_->twin, c);
    const auto nt = static_cast<Eigen::Index>(twin.times.size());
    Eigen::VectorXd times(nt - 1);
    for (Eigen::Index k = 1; k < nt; ++k) times(k - 1) = twin.times[static_cast<std::size_t>(k)];
    // Readings far from the model: ignored by a zero gain.
    const Eigen::MatrixXd readings =
        Eigen::MatrixXd::Constant(nt - 1, static_cast<Eigen::Index>(kSensors.size()), 400.0);
    const solvers::ObserverRun run =
        solvers::observe(s_->twin.model.system, c, setup(n), times, readings);
    const double scale = twin.states.cwiseAbs().maxCoeff();
    EXPECT_LE((run.states - twin.states.rightCols(nt - 1)).cwiseAbs().maxCoeff(), 1e-11 * scale)
        << "scheme " << static_cast<int>(scheme);
    const Eigen::Index first = s_->twin.outputs.temperatures;
    const Eigen::MatrixXd tcp = twin.outputs.middleCols(first, 3).bottomRows(nt - 1).rowwise() -
                                twin.outputs.middleCols(first, 3).row(0);
    EXPECT_LE((run.drift.leftCols(3) - tcp).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_GT(tcp.col(1).cwiseAbs().maxCoeff(), 1e-6);  // a drift of microns was compared
    EXPECT_EQ(run.drift_sigma.maxCoeff(), 0.0);
    if (scheme != core::TimeScheme::backward_euler) continue;
    // Readings between the grid's steps cut a step there and land on the same trajectory.
    Eigen::VectorXd off = times.array() - 5.0;
    const solvers::ObserverRun cut =
        solvers::observe(s_->twin.model.system, c, setup(n), off, readings);
    EXPECT_LE((cut.drift - run.drift).cwiseAbs().maxCoeff(), 0.05 * tcp.cwiseAbs().maxCoeff());
  }
}

/// Share of the samples (after the first) whose |estimate - truth| <= 2 sigma, per TCP direction.
Eigen::Vector3d coverage(const solvers::ObserverRun& run, const io::MeasuredRun& truth) {
  Eigen::Vector3d in = Eigen::Vector3d::Zero();
  const Eigen::Index n = truth.time.size();
  for (Eigen::Index i = 1; i < n; ++i)
    for (int d = 0; d < 3; ++d)
      in(d) += std::abs(run.drift(i, d) - truth.displacement(i, d)) <= 2 * run.drift_sigma(i, d);
  return in / static_cast<double>(n - 1);
}

TEST_F(Observer, TwoSigmaCoversTheTrueDriftOnACleanRun) {
  const core::CaseSpec c = run_spec();
  const solvers::ObserverRun run = solvers::observe(
      s_->twin.model.system, c, setup(default_noise()), s_->clean.time, s_->clean.temperature);
  const io::MeasuredRun& truth = s_->clean_truth;  // full order, no noise
  const Eigen::Vector3d cov = coverage(run, truth);
  std::cerr << "coverage dx " << cov(0) << " dy " << cov(1) << " dz " << cov(2) << "\n";
  for (int d = 1; d < 3; ++d) {
    EXPECT_GE(cov(d), 0.85) << "direction " << d;
    EXPECT_LE(cov(d), 1.0) << "direction " << d;
  }
  // Sharp, not only wide: sigma is a few per cent of the drift's range, and the errors are of
  // the size sigma says (an RMS error to mean sigma ratio near 1, not 0.1).
  for (int d = 1; d < 3; ++d) {
    const double range = truth.displacement.col(d).cwiseAbs().maxCoeff();
    const double mean_sigma = run.drift_sigma.col(d).mean();
    const double rms =
        std::sqrt((run.drift.col(d) - truth.displacement.col(d)).squaredNorm() / run.drift.rows());
    std::cerr << "d" << d << ": range " << range << " mean sigma " << mean_sigma << " rms " << rms
              << "\n";
    EXPECT_LE(mean_sigma, 0.1 * range) << "direction " << d;
    EXPECT_GE(rms / mean_sigma, 0.2) << "direction " << d;
  }
  EXPECT_FALSE(run.recalibrate) << "clean run: alarm raised at " << run.recalibrate_at_s << " s";
}

TEST_F(Observer, RecalibrateOnAnUndeclaredHeatInputNotOnACleanRun) {
  const core::CaseSpec c = run_spec();
  const solvers::ObserverRun clean = solvers::observe(
      s_->twin.model.system, c, setup(default_noise()), s_->clean.time, s_->clean.temperature);
  const solvers::ObserverRun heat = solvers::observe(
      s_->twin.model.system, c, setup(default_noise()), s_->heat.time, s_->heat.temperature);
  std::cerr << "clean: max window NIS / bound "
            << (clean.window_nis.array() / clean.window_bound.array()).maxCoeff()
            << "; heat: alarm at " << heat.recalibrate_at_s << " s since "
            << heat.recalibrate_since_s << " s\n";
  EXPECT_FALSE(clean.recalibrate);
  ASSERT_TRUE(heat.recalibrate);
  EXPECT_LE(heat.recalibrate_at_s, 2 * 3600.0);
  // The heat is there from t = 0: the change point is dated within the first NIS window (1800 s),
  // not at the alarm. Its date is sensitive: 60 s on the branch's build, 1020 s once Eigen was
  // compiled for the CPU (-march=native), the same data otherwise.
  EXPECT_LE(heat.recalibrate_since_s, 1800.0);
  EXPECT_LE(heat.recalibrate_since_s, heat.recalibrate_at_s - 900.0);
  // The readings leave the declared model's own run (3 sigma held for 900 s) before the NIS
  // window says so: the unknown inputs follow the heat, the declared run does not.
  EXPECT_TRUE(clean.model_departures.empty());
  ASSERT_FALSE(heat.model_departures.empty());
  EXPECT_EQ(heat.recalibrate_at_s, heat.model_departures.front().raised_s);
  solvers::ObserverSetup nis_only = setup(default_noise());
  nis_only.consistency.model_residual_sigmas = 0;
  const solvers::ObserverRun by_nis =
      solvers::observe(s_->twin.model.system, c, nis_only, s_->heat.time, s_->heat.temperature);
  std::cerr << "heat, the NIS test alone: alarm at " << by_nis.recalibrate_at_s << " s\n";
  ASSERT_TRUE(by_nis.recalibrate);
  EXPECT_TRUE(by_nis.model_departures.empty());
  EXPECT_LT(heat.recalibrate_at_s, by_nis.recalibrate_at_s);
}

TEST_F(Observer, MissingReadingsAreLeftOutOfTheUpdate) {
  // One sensor silent for the second half, every sensor missing at one sample: the update uses
  // what is there (the readings' count says so) and the drift stays within its 2 sigma.
  const core::CaseSpec c = run_spec();
  Eigen::MatrixXd y = s_->clean.temperature;
  const Eigen::Index n = y.rows(), half = n / 2;
  y.col(2).tail(n - half).setConstant(std::numeric_limits<double>::quiet_NaN());
  y.row(10).setConstant(std::numeric_limits<double>::quiet_NaN());
  const solvers::ObserverRun run =
      solvers::observe(s_->twin.model.system, c, setup(default_noise()), s_->clean.time, y);
  const int m = static_cast<int>(kSensors.size());
  EXPECT_EQ(run.dof(0), m);
  EXPECT_EQ(run.dof(10), 0);
  EXPECT_EQ(run.nis(10), 0.0);
  EXPECT_EQ(run.dof(n - 1), m - 1);
  EXPECT_TRUE(std::isnan(run.innovation(n - 1, 2)));
  EXPECT_TRUE(run.drift.allFinite());
  const Eigen::Vector3d cov = coverage(run, s_->clean_truth);
  EXPECT_GE(cov(1), 0.85);
  EXPECT_GE(cov(2), 0.85);
  EXPECT_FALSE(run.recalibrate);
}

TEST_F(Observer, CalibratedSigmaMakesTheTrainingErrorsNormalAndLeavesTheFilter) {
  // The scale from a run's normalised squared errors, applied, makes their mean 1 on that run;
  // the estimates, innovations and alarm do not move.
  const core::CaseSpec c = run_spec();
  const solvers::ObserverSetup plain = setup(default_noise());
  const std::vector<solvers::ObserverRun> runs{
      solvers::observe(s_->twin.model.system, c, plain, s_->clean.time, s_->clean.temperature)};
  const Eigen::MatrixXd truth = clean_tcp_truth(runs[0]);
  const std::vector<Eigen::MatrixXd> truths{truth};
  const Eigen::VectorXd nees = solvers::mean_normalised_squared_error(runs, truths);
  const Eigen::VectorXd scale = solvers::drift_sigma_calibration(runs, truths);
  std::cerr << "normalised squared error dx " << nees(0) << " dy " << nees(1) << " dz " << nees(2)
            << "\n";
  ASSERT_EQ(scale.size(), truth.cols());
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(scale(d), std::sqrt(nees(d)), 1e-12);
  for (Eigen::Index d = 3; d < truth.cols(); ++d) EXPECT_EQ(scale(d), 1.0);  // no truth: kept
  solvers::ObserverSetup calibrated = plain;
  calibrated.noise.drift_sigma_scale = scale;
  const std::vector<solvers::ObserverRun> again{solvers::observe(
      s_->twin.model.system, c, calibrated, s_->clean.time, s_->clean.temperature)};
  const Eigen::VectorXd after = solvers::mean_normalised_squared_error(again, truths);
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(after(d), 1.0, 1e-9) << "direction " << d;
  EXPECT_EQ(again[0].drift, runs[0].drift);
  EXPECT_EQ(again[0].nis, runs[0].nis);
  EXPECT_EQ(again[0].recalibrate, runs[0].recalibrate);
  // A known noise on the truth is taken out; sizes that differ are refused.
  const Eigen::VectorXd noisy = solvers::mean_normalised_squared_error(runs, truths, 0.01e-6);
  EXPECT_LT(noisy(1), nees(1));
  EXPECT_THROW(solvers::mean_normalised_squared_error(runs, {truths[0].leftCols(2)}),
               core::SolverError);
  calibrated.noise.drift_sigma_scale = Eigen::VectorXd::Ones(truth.cols() + 1);
  EXPECT_THROW(solvers::KalmanObserver(s_->twin.model.system, c, calibrated), core::SolverError);
}

TEST_F(Observer, CoverageCalibrationAndWideningOnInconsistency) {
  // The coverage calibration is the smallest factor under which 95 % of the training run's
  // samples lie within ±2σ: applied, they do; 1 % less, they do not.
  const core::CaseSpec c = run_spec();
  const solvers::ObserverSetup plain = setup(default_noise());
  const std::vector<solvers::ObserverRun> runs{
      solvers::observe(s_->twin.model.system, c, plain, s_->clean.time, s_->clean.temperature)};
  const Eigen::MatrixXd truth = clean_tcp_truth(runs[0]);
  const Eigen::VectorXd scale = solvers::drift_sigma_coverage_calibration(runs, {truth}, 0.95);
  for (int d = 0; d < 3; ++d) {
    double in = 0, in_less = 0, n = 0;
    for (Eigen::Index i = 1; i < truth.rows(); ++i) {
      const double e = std::abs(runs[0].drift(i, d) - truth(i, d)), s = runs[0].drift_sigma(i, d);
      in += e <= 2 * scale(d) * s;
      in_less += e <= 2 * 0.99 * scale(d) * s;
      n += 1;
    }
    EXPECT_GE(in / n, 0.95) << "direction " << d;
    EXPECT_LT(in_less / n, 0.95) << "direction " << d;
  }
  for (Eigen::Index d = 3; d < truth.cols(); ++d) EXPECT_EQ(scale(d), 1.0);  // no truth: kept
  const Eigen::VectorXd twice =
      solvers::drift_sigma_coverage_calibration(runs, {truth}, 0.95, 2 * scale);
  for (Eigen::Index d = 0; d < scale.size(); ++d)
    EXPECT_NEAR(twice(d), 2 * scale(d) * scale(d), 1e-12);
  EXPECT_THROW(solvers::drift_sigma_coverage_calibration(runs, {truth}, 1.0), core::SolverError);
  // drift_band_score scores the same band: with the factor, at least 95 %; 1 % less, below. A
  // truth measured with white noise widens the band by it (±2 sqrt((factor sigma)^2 + noise^2)).
  const solvers::DriftBandScore held = solvers::drift_band_score(runs, {truth}, scale);
  const solvers::DriftBandScore less = solvers::drift_band_score(runs, {truth}, 0.99 * scale);
  const double noise = 1e-3 * runs[0].drift_sigma.col(2).maxCoeff();
  const solvers::DriftBandScore noisy =
      solvers::drift_band_score(runs, {truth}, 0.99 * scale, noise);
  for (int d = 0; d < 3; ++d) {
    EXPECT_GE(held.coverage(d), 0.95) << "direction " << d;
    EXPECT_LT(less.coverage(d), 0.95) << "direction " << d;
    EXPECT_GE(noisy.coverage(d), less.coverage(d)) << "direction " << d;
    EXPECT_EQ(held.samples(d), truth.rows() - 1) << "direction " << d;
  }
  Eigen::MatrixXd no_dz = truth;
  no_dz.col(2).setConstant(std::numeric_limits<double>::quiet_NaN());
  const solvers::DriftBandScore unscored = solvers::drift_band_score(runs, {no_dz});
  EXPECT_EQ(unscored.samples(2), 0);
  EXPECT_TRUE(std::isnan(unscored.coverage(2)) && std::isnan(unscored.rms_error_m(2)));

  // Widening: on the run with an undeclared heat input, where the innovations outgrow the noise
  // model, the reported sigma is sqrt(window NIS / dof) times the plain one when that is above
  // 1, the plain one otherwise; the estimate, innovations and alarm are the filter's own.
  solvers::ObserverSetup widened = plain;
  widened.noise.widen_on_inconsistency = true;
  const solvers::ObserverRun heat =
      solvers::observe(s_->twin.model.system, c, plain, s_->heat.time, s_->heat.temperature);
  const solvers::ObserverRun wide =
      solvers::observe(s_->twin.model.system, c, widened, s_->heat.time, s_->heat.temperature);
  EXPECT_EQ(wide.drift, heat.drift);
  EXPECT_EQ(wide.nis, heat.nis);
  EXPECT_EQ(wide.recalibrate_at_s, heat.recalibrate_at_s);
  Eigen::VectorXi dof_window = Eigen::VectorXi::Zero(heat.dof.size());
  double widest = 1;
  for (Eigen::Index i = 0; i < heat.dof.size(); ++i) {
    // The window's readings: those of the samples within window_s before this one.
    for (Eigen::Index j = 0; j <= i; ++j)
      if (heat.times(j) > heat.times(i) - plain.consistency.window_s) dof_window(i) += heat.dof(j);
    const double f = std::sqrt(std::max(1.0, heat.window_nis(i) / dof_window(i)));
    widest = std::max(widest, f);
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(wide.drift_sigma(i, d), f * heat.drift_sigma(i, d), 1e-12 * f * 1e-3)
          << "sample " << i << " direction " << d;
  }
  // Where the alarm is raised the window's NIS is above its chi-square bound (about 1.13 times
  // its readings here): the heat input's innovations did widen it.
  ASSERT_TRUE(heat.recalibrate);
  EXPECT_GT(widest, 1.1);
  const solvers::ObserverRun clean_wide =
      solvers::observe(s_->twin.model.system, c, widened, s_->clean.time, s_->clean.temperature);
  // On the clean run, once the window is full, the widening stays small: the noise model holds.
  double clean_widest = 1;
  for (Eigen::Index i = 0; i < clean_wide.times.size(); ++i)
    if (clean_wide.times(i) >= plain.consistency.window_s)
      clean_widest =
          std::max(clean_widest, clean_wide.drift_sigma(i, 1) / runs[0].drift_sigma(i, 1));
  std::cerr << "widening: at most " << widest << " on the heat run, " << clean_widest
            << " on the clean run\n";
  EXPECT_LE(clean_widest, 1.3);
}

/// The final estimate and sigma of the unknown input `name` of a run.
std::pair<double, double> final_input(const solvers::ObserverRun& run, const std::string& name) {
  const auto& names = run.unknown_input_names;
  const auto it = std::find(names.begin(), names.end(), name);
  EXPECT_NE(it, names.end()) << name;
  if (it == names.end()) return {std::numeric_limits<double>::quiet_NaN(), 0};
  const auto b = it - names.begin();
  const Eigen::Index last = run.times.size() - 1;
  return {run.unknown_inputs(last, b), run.unknown_inputs_sigma(last, b)};
}

/// The largest |heat input| at a run's end [W].
double largest_heat(const solvers::ObserverRun& run) {
  double out = 0;
  for (std::size_t b = 0; b < run.unknown_input_names.size(); ++b)
    if (run.unknown_input_names[b].starts_with("heat:"))
      out = std::max(
          out, std::abs(run.unknown_inputs(run.times.size() - 1, static_cast<Eigen::Index>(b))));
  return out;
}

TEST_F(Observer, ASensorOffsetIsEstimatedAsAnOffsetNotAsHeat) {
  // The clean run with 0.5 K added to T17's readings from t = 0. Without offset states the filter
  // reads it as heat (large heat inputs, a drift error many times the clean run's); with them
  // the offset is estimated as T17's (0.5 K within 3 sigma, the others near 0), the heat inputs
  // stay as small as on the clean run, and the drift is as good as on the clean run.
  const core::CaseSpec c = run_spec();
  const Eigen::Index faulty = 4;  // T17
  ASSERT_EQ(kSensors[faulty], "T17");
  Eigen::MatrixXd y = s_->clean.temperature;
  y.col(faulty).array() += 0.5;
  solvers::ObserverNoise with = default_noise();
  with.sensor_offset_initial_k = 0.5;
  with.sensor_offset_walk_k = 0.05;
  const auto& sys = s_->twin.model.system;
  const solvers::ObserverRun plain =
      solvers::observe(sys, c, setup(default_noise()), s_->clean.time, y);
  const solvers::ObserverRun offset = solvers::observe(sys, c, setup(with), s_->clean.time, y);
  const solvers::ObserverRun clean =
      solvers::observe(sys, c, setup(with), s_->clean.time, s_->clean.temperature);
  // Names: the offsets follow the heat inputs and the air, one per sensor; none without them.
  for (const auto& n : plain.unknown_input_names) EXPECT_FALSE(n.starts_with("offset:")) << n;
  ASSERT_EQ(offset.unknown_input_names.size(), plain.unknown_input_names.size() + kSensors.size());
  EXPECT_EQ(offset.unknown_input_names.back(), "offset:" + kSensors.back());

  const auto [o, so] = final_input(offset, "offset:T17");
  std::cerr << "T17 offset " << o << " (" << so << "); largest heat: plain " << largest_heat(plain)
            << " W, with offsets " << largest_heat(offset) << " W, clean " << largest_heat(clean)
            << " W\n";
  EXPECT_NEAR(o, 0.5, std::max(3 * so, 0.03));
  EXPECT_LT(so, 0.1);
  for (const auto& id : kSensors) {
    if (id == "T17") continue;
    const auto [v, sv] = final_input(offset, "offset:" + id);
    EXPECT_LT(std::abs(v), std::max(3 * sv, 0.05)) << id;
    const auto [vc, svc] = final_input(clean, "offset:" + id);
    EXPECT_LT(std::abs(vc), std::max(3 * svc, 0.05)) << id << " on the clean run";
  }
  EXPECT_LT(largest_heat(offset), 0.25 * largest_heat(plain));
  EXPECT_LT(largest_heat(offset), 2 * largest_heat(clean) + 1.0);

  const auto rms = [&](const solvers::ObserverRun& run, int d) {
    return std::sqrt((run.drift.col(d) - s_->clean_truth.displacement.col(d)).squaredNorm() /
                     static_cast<double>(run.drift.rows()));
  };
  for (int d = 1; d < 3; ++d) {
    std::cerr << "d" << d << " RMS: plain " << rms(plain, d) << ", with offsets " << rms(offset, d)
              << ", clean " << rms(clean, d) << "\n";
    EXPECT_LT(rms(offset, d), 0.5 * rms(plain, d)) << "direction " << d;
    EXPECT_LT(rms(offset, d), 1.5 * rms(clean, d) + 0.02e-6) << "direction " << d;
  }
  const Eigen::Vector3d cov = coverage(offset, s_->clean_truth);
  EXPECT_GE(cov(1), 0.85);
  EXPECT_GE(cov(2), 0.85);
  EXPECT_FALSE(offset.recalibrate)
      << "the offset is explained: alarm at " << offset.recalibrate_at_s << " s";
  EXPECT_FALSE(clean.recalibrate);
  // The offset is sure (0.5 K against a sigma under 0.1 K): T17 alone is reported faulty, from
  // the first readings (the known start shows an offset at once) and raised after the sustain.
  ASSERT_EQ(offset.sensor_faults.size(), 1u);
  EXPECT_EQ(offset.sensor_faults[0].sensor, faulty);
  EXPECT_LE(offset.sensor_faults[0].since_s, 600.0);
  EXPECT_GE(offset.sensor_faults[0].raised_s - offset.sensor_faults[0].since_s,
            solvers::ConsistencyOptions{}.sustain_s);
  EXPECT_TRUE(clean.sensor_faults.empty()) << "sensor " << clean.sensor_faults[0].sensor;
  EXPECT_TRUE(plain.sensor_faults.empty());  // no offset states, no offset test
  // A negative or infinite offset spread, or fault bound, is refused.
  solvers::ObserverSetup no_bound = setup(with);
  no_bound.consistency.sensor_fault_sigmas = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(solvers::KalmanObserver(sys, c, no_bound), core::SolverError);
  no_bound.consistency.sensor_fault_sigmas = 4;
  no_bound.consistency.model_residual_sigmas = -1;
  EXPECT_THROW(solvers::KalmanObserver(sys, c, no_bound), core::SolverError);
  no_bound.consistency.model_residual_sigmas = 3;
  no_bound.consistency.departure_onset_sigmas = std::numeric_limits<double>::infinity();
  EXPECT_THROW(solvers::KalmanObserver(sys, c, no_bound), core::SolverError);
  solvers::ObserverSetup bad = setup(with);
  bad.noise.sensor_offset_walk_k = -0.1;
  EXPECT_THROW(solvers::KalmanObserver(sys, c, bad), core::SolverError);
}

TEST_F(Observer, AnOffsetThatAppearsLateAlsoSaysRecalibrate) {
  // T17 reads high by 0.25 K per hour from 1 h on (a sensor drifting, or heat growing beside that
  // one sensor: the filter cannot tell them apart). Its offset state and the heat inputs follow
  // it with consistent innovations, so the NIS test raises nothing; the offset crosses the fault
  // bound hours in. Not there from the start, it is reported as T17's fault and as recalibrate,
  // dated from its crossing; the same offset from t = 0 (above) raises the fault alone. Before
  // the offset is sure, T17 already reads away from the declared model's run (less its offset's
  // estimate so far): that test says recalibrate first.
  const core::CaseSpec c = run_spec();
  const Eigen::Index faulty = 4;  // T17
  Eigen::MatrixXd y = s_->clean.temperature;
  for (Eigen::Index i = 0; i < y.rows(); ++i)
    y(i, faulty) += 0.25 * std::max(0.0, s_->clean.time(i) / 3600 - 1);
  solvers::ObserverSetup with = setup(default_noise());
  with.noise.sensor_offset_initial_k = 0.5;
  with.noise.sensor_offset_walk_k = 0.05;
  const auto& sys = s_->twin.model.system;
  const solvers::ObserverRun late = solvers::observe(sys, c, with, s_->clean.time, y);
  ASSERT_EQ(late.sensor_faults.size(), 1u);
  const solvers::HeldSensor& f = late.sensor_faults.front();
  std::cerr << "T17 drifting from 3600 s: fault since " << f.since_s << " s, raised at "
            << f.raised_s << " s; recalibrate at " << late.recalibrate_at_s << " s since "
            << late.recalibrate_since_s << " s\n";
  EXPECT_EQ(f.sensor, faulty);
  EXPECT_GT(f.since_s, 3600.0);
  ASSERT_TRUE(late.recalibrate);
  ASSERT_FALSE(late.model_departures.empty());
  EXPECT_EQ(late.model_departures.front().sensor, faulty);
  EXPECT_EQ(late.recalibrate_at_s, late.model_departures.front().raised_s);
  EXPECT_GT(late.recalibrate_since_s, 3600.0);
  EXPECT_LT(late.recalibrate_at_s, f.raised_s);
  // Without the declared run's test the late fault says it, dated from the offset's crossing.
  with.consistency.model_residual_sigmas = 0;
  const solvers::ObserverRun by_fault = solvers::observe(sys, c, with, s_->clean.time, y);
  ASSERT_TRUE(by_fault.recalibrate);
  EXPECT_EQ(by_fault.recalibrate_at_s, f.raised_s);
  EXPECT_EQ(by_fault.recalibrate_since_s, f.since_s);
  with.consistency.sensor_fault_sigmas = 0;  // neither test: the innovations alone say nothing
  EXPECT_FALSE(solvers::observe(sys, c, with, s_->clean.time, y).recalibrate);
}

TEST_F(Observer, DriftSigmaGrowsWithTheDriftRowsRelativeError) {
  // The drift rows' own error e (ObserverNoise::drift_relative_sigma): the reported sigma is
  // sqrt(sigma_0^2 + (e d)^2), sigma_0 the filter's; the estimate is the same.
  const core::CaseSpec c = run_spec();
  solvers::ObserverNoise rel = default_noise();
  rel.drift_relative_sigma = 0.05;
  const auto& sys = s_->twin.model.system;
  const solvers::ObserverRun plain =
      solvers::observe(sys, c, setup(default_noise()), s_->clean.time, s_->clean.temperature);
  const solvers::ObserverRun wide =
      solvers::observe(sys, c, setup(rel), s_->clean.time, s_->clean.temperature);
  EXPECT_EQ(wide.drift, plain.drift);
  for (Eigen::Index i = 0; i < plain.times.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      const double s0 = plain.drift_sigma(i, d), e = 0.05 * plain.drift(i, d);
      EXPECT_NEAR(wide.drift_sigma(i, d), std::sqrt(s0 * s0 + e * e), 1e-9 * s0 + 1e-15)
          << "sample " << i << " direction " << d;
    }
  // Where the drift is large against the filter's sigma, the relative part dominates.
  const Eigen::Index last = plain.times.size() - 1;
  EXPECT_GT(wide.drift_sigma(last, 2), plain.drift_sigma(last, 2));
}

TEST_F(Observer, CorrectionSigmaFollowsWhatTheFilterMovedFromTheDeclaredRun) {
  // ObserverNoise::correction_relative_sigma c: sigma^2 = sigma_0^2 + (c (d - d_open))^2, d_open
  // the declared model's own run (the observer with every reading missing and no unknown input
  // keeps its mean there); the estimate is the same. On the run with an undeclared heat input the
  // filter moves the drift far from the declared run, on the clean run hardly.
  const core::CaseSpec c = run_spec();
  const auto& sys = s_->twin.model.system;
  solvers::ObserverNoise corr = default_noise();
  corr.correction_relative_sigma = 0.5;
  for (const auto* run : {&s_->clean, &s_->heat}) {
    const solvers::ObserverRun plain =
        solvers::observe(sys, c, setup(default_noise()), run->time, run->temperature);
    const solvers::ObserverRun wide =
        solvers::observe(sys, c, setup(corr), run->time, run->temperature);
    const Eigen::MatrixXd none = Eigen::MatrixXd::Constant(
        run->temperature.rows(), run->temperature.cols(), std::numeric_limits<double>::quiet_NaN());
    const solvers::ObserverRun open =
        solvers::observe(sys, c, setup(default_noise()), run->time, none);
    EXPECT_EQ(wide.drift, plain.drift);
    for (Eigen::Index i = 0; i < plain.times.size(); ++i)
      for (int d = 0; d < 3; ++d) {
        const double s0 = plain.drift_sigma(i, d);
        const double e = 0.5 * (plain.drift(i, d) - open.drift(i, d));
        EXPECT_NEAR(wide.drift_sigma(i, d), std::sqrt(s0 * s0 + e * e), 1e-8 * (s0 + std::abs(e)))
            << "sample " << i << " direction " << d;
      }
    const Eigen::Index last = plain.times.size() - 1;
    const double moved = std::abs(plain.drift(last, 2) - open.drift(last, 2));
    std::cerr << (run == &s_->heat ? "heat" : "clean") << " run: dz moved " << moved * 1e6
              << " um from the declared run, of " << std::abs(plain.drift(last, 2)) * 1e6
              << " um\n";
    if (run == &s_->heat)
      EXPECT_GT(moved, 0.05 * std::abs(plain.drift(last, 2)));
    else
      EXPECT_LT(moved, 0.05 * std::abs(plain.drift(last, 2)));
  }
  solvers::ObserverSetup bad = setup(corr);
  bad.noise.correction_relative_sigma = -1;
  EXPECT_THROW(solvers::KalmanObserver(sys, c, bad), core::SolverError);
}

TEST_F(Observer, SigmaTermsGiveTheSigmaOfAnyCorrectionAndExpansionSigma) {
  // The run keeps per sample what its sigma is made of (DriftSigmaTerms), so that `observe
  // --changed` scores other c and e without observing again: the terms of a run observed with
  // c = e = 0 give, through solvers::drift_sigma, the sigma of a run observed with c = 0.7 and
  // e = (0.1, 0.2, ...), widening on inconsistency included; and the terms do not depend on c, e.
  // With the terms after the alarm they act from the alarm on; on evidence, weighted by the
  // readings' departure before it.
  const core::CaseSpec c = run_spec();
  const auto& sys = s_->twin.model.system;
  solvers::ObserverNoise plain_noise = default_noise();
  plain_noise.widen_on_inconsistency = true;
  const solvers::ObserverSetup plain_setup = setup(plain_noise);
  ASSERT_FALSE(plain_setup.target_expansion.empty());
  solvers::ObserverNoise wide_noise = plain_noise;
  wide_noise.correction_relative_sigma = 0.7;
  wide_noise.expansion_relative_sigma = Eigen::VectorXd::LinSpaced(
      static_cast<Eigen::Index>(plain_setup.target_expansion.size()), 0.1,
      0.1 * static_cast<double>(plain_setup.target_expansion.size()));
  const auto& run = s_->heat;
  const solvers::ObserverRun plain =
      solvers::observe(sys, c, plain_setup, run.time, run.temperature);
  const solvers::ObserverRun wide =
      solvers::observe(sys, c, setup(wide_noise), run.time, run.temperature);
  ASSERT_EQ(plain.sigma_terms.size(), static_cast<std::size_t>(plain.times.size()));
  EXPECT_EQ(wide.drift, plain.drift);
  double widened = 1;
  for (Eigen::Index i = 0; i < plain.times.size(); ++i) {
    const solvers::DriftSigmaTerms& t = plain.sigma_terms[static_cast<std::size_t>(i)];
    widened = std::max(widened, t.widening);
    EXPECT_EQ(plain.drift_sigma.row(i).transpose(), solvers::drift_sigma(t, 0, {})) << i;
    const Eigen::VectorXd expected =
        solvers::drift_sigma(t, 0.7, wide_noise.expansion_relative_sigma);
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(wide.drift_sigma(i, d), expected(d), 1e-12 * expected(d)) << i << " " << d;
  }
  EXPECT_GT(widened, 1.0);  // the heat run's innovations widen the sigma somewhere
  // With the terms after the alarm (ChangedTermsGate::after_alarm): the plain sigma until the
  // filter says recalibrate, the wide one from then on.
  ASSERT_TRUE(plain.recalibrate);
  wide_noise.changed_terms = solvers::ChangedTermsGate::after_alarm;
  const solvers::ObserverRun gated =
      solvers::observe(sys, c, setup(wide_noise), run.time, run.temperature);
  EXPECT_EQ(gated.recalibrate_at_s, plain.recalibrate_at_s);
  for (Eigen::Index i = 0; i < plain.times.size(); ++i) {
    const bool alarm = plain.times(i) >= plain.recalibrate_at_s;
    EXPECT_EQ(plain.sigma_terms[static_cast<std::size_t>(i)].alarm, alarm) << i;
    const Eigen::MatrixXd& expected = alarm ? wide.drift_sigma : plain.drift_sigma;
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(gated.drift_sigma(i, d), expected(i, d), 1e-12 * expected(i, d)) << i << " " << d;
  }
  // On evidence: before the alarm the terms' variance times the evidence squared (sigma^2 =
  // plain^2 + w^2 (wide^2 - plain^2)), all of it from the alarm on. The heat run departs from
  // the declared run before the alarm (which waits for 3 sigma held for sustain_s).
  wide_noise.changed_terms = solvers::ChangedTermsGate::on_evidence;
  const solvers::ObserverRun weighted =
      solvers::observe(sys, c, setup(wide_noise), run.time, run.temperature);
  int partly = 0;
  for (Eigen::Index i = 0; i < plain.times.size(); ++i) {
    const solvers::DriftSigmaTerms& t = plain.sigma_terms[static_cast<std::size_t>(i)];
    EXPECT_EQ(weighted.sigma_terms[static_cast<std::size_t>(i)].evidence, t.evidence) << i;
    ASSERT_GE(t.evidence, 0.0);
    ASSERT_LE(t.evidence, 1.0);
    const double w = t.alarm ? 1.0 : t.evidence;
    EXPECT_EQ(solvers::changed_terms_weight(t, solvers::ChangedTermsGate::on_evidence), w);
    if (!t.alarm && w > 0 && w < 1) ++partly;
    for (int d = 0; d < 3; ++d) {
      const double p2 = std::pow(plain.drift_sigma(i, d), 2);
      const double expected = std::sqrt(p2 + w * w * (std::pow(wide.drift_sigma(i, d), 2) - p2));
      EXPECT_NEAR(weighted.drift_sigma(i, d), expected, 1e-9 * expected) << i << " " << d;
    }
  }
  EXPECT_GT(partly, 0);
  EXPECT_EQ(plain.sigma_terms.front().evidence, 0.0);  // the run starts at the declared state
}

TEST_F(Observer, EvidenceOfOtherSettingsIsWhatTheObserverSaysWithThem) {
  // The run keeps each sample's departure (the departure test's residual over the sensor's
  // sigma), so that `observe --changed` scores other evidence settings without observing again:
  // solvers::evidence_of gives the evidence of a run observed with those settings.
  const core::CaseSpec c = run_spec();
  const auto& sys = s_->twin.model.system;
  const auto& run = s_->heat;
  const solvers::ObserverSetup own = setup(default_noise());
  const solvers::ObserverRun plain = solvers::observe(sys, c, own, run.time, run.temperature);
  const auto m = own.sensor_rows.rows();
  for (const solvers::DriftSigmaTerms& t : plain.sigma_terms) ASSERT_EQ(t.departure.size(), m);
  const solvers::ConsistencyOptions& k = own.consistency;
  const Eigen::VectorXd same = solvers::evidence_of(plain, solvers::evidence_settings(k));
  double largest = 0;
  for (Eigen::Index i = 0; i < plain.times.size(); ++i) {
    EXPECT_NEAR(same(i), plain.sigma_terms[static_cast<std::size_t>(i)].evidence, 1e-9) << i;
    largest = std::max(largest, same(i));
  }
  EXPECT_GT(largest, 0.5);  // the heat run departs
  solvers::ObserverSetup other = own;
  other.consistency.evidence_time_s = 60;
  other.consistency.evidence_onset_sigmas = 0.5;
  const solvers::ObserverRun quick = solvers::observe(sys, c, other, run.time, run.temperature);
  const Eigen::VectorXd rescored =
      solvers::evidence_of(plain, {60, 0.5, other.consistency.model_residual_sigmas});
  int differs = 0;
  for (Eigen::Index i = 0; i < plain.times.size(); ++i) {
    EXPECT_NEAR(rescored(i), quick.sigma_terms[static_cast<std::size_t>(i)].evidence, 1e-9) << i;
    differs += std::abs(rescored(i) - same(i)) > 1e-3;
  }
  EXPECT_GT(differs, 0);
  // Of the residual itself, from 0: the largest |departure| over the bound, clamped.
  const Eigen::VectorXd raw = solvers::evidence_of(plain, {0, 0, 3});
  for (Eigen::Index i = 0; i < plain.times.size(); ++i) {
    const Eigen::VectorXd& z = plain.sigma_terms[static_cast<std::size_t>(i)].departure;
    EXPECT_NEAR(raw(i), std::min(1.0, z.array().abs().maxCoeff() / 3), 1e-12) << i;
  }
}

TEST(WindowMean, AveragesTheFiniteValuesWithinHalfTheWindowOnEitherSide) {
  // The measured drift's mean over a window (studies::window_mean): the averaged coverage rule
  // reads it where the drift's white noise is declared. Uneven times, a missing value, edges.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd times(6);
  times << 0, 60, 120, 150, 300, 600;
  Eigen::MatrixXd values(6, 2);
  values << 1, 10,  //
      2, nan,       //
      3, 30,        //
      4, 40,        //
      5, 50,        //
      6, 60;
  const Eigen::MatrixXd m = studies::window_mean(values, times, 300);
  EXPECT_DOUBLE_EQ(m(0, 0), (1 + 2 + 3 + 4) / 4.0);      // 0 .. 150
  EXPECT_DOUBLE_EQ(m(1, 0), (1 + 2 + 3 + 4) / 4.0);      // -90 .. 210
  EXPECT_DOUBLE_EQ(m(2, 0), (1 + 2 + 3 + 4) / 4.0);      // -30 .. 270
  EXPECT_DOUBLE_EQ(m(3, 0), (1 + 2 + 3 + 4 + 5) / 5.0);  // 0 .. 300, both ends in
  EXPECT_DOUBLE_EQ(m(4, 0), (4 + 5) / 2.0);              // 150 .. 450
  EXPECT_DOUBLE_EQ(m(5, 0), 6.0);                        // alone
  EXPECT_DOUBLE_EQ(m(0, 1), (10 + 30 + 40) / 3.0);       // the missing value left out
  EXPECT_TRUE(std::isnan(m(1, 1)));                      // and not filled in
  EXPECT_EQ(studies::window_mean(values, times, 0).col(0), values.col(0));  // no window
}

TEST(ExponentialMean, FollowsAStepWithItsTimeConstantAndSkipsMissingValues) {
  // mean += (1 - exp(-dt / tau)) (value - mean), dt since the sensor's last value, from its first
  // value on; NaN leaves the mean.
  solvers::ExponentialMean mean(100);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(mean.add(0, Eigen::Vector2d(1, 2)), Eigen::Vector2d(1, 2));
  const Eigen::VectorXd at100 = mean.add(100, Eigen::Vector2d(0, nan));
  EXPECT_NEAR(at100(0), std::exp(-1.0), 1e-15);
  EXPECT_TRUE(std::isnan(at100(1)));
  const Eigen::VectorXd at300 = mean.add(300, Eigen::Vector2d(0, 4));
  EXPECT_NEAR(at300(0), std::exp(-3.0), 1e-15);
  EXPECT_NEAR(at300(1), 2 + (1 - std::exp(-3.0)) * 2, 1e-15);  // the 300 s since its last value
  solvers::ExponentialMean none(0);
  none.add(0, Eigen::Vector2d(1, 2));
  EXPECT_EQ(none.add(10, Eigen::Vector2d(5, 6)), Eigen::Vector2d(5, 6));
}

TEST(DepartureEvidence, RampsFromTheOnsetBoundToTheAlarmBound) {
  // The largest |residual| / sigma over the sensors (NaN left out), 0 at `onset`, 1 at `bound`.
  const Eigen::Vector3d sigma(0.1, 0.2, 0.05);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(solvers::departure_evidence(Eigen::Vector3d(0.05, -0.1, 0.0), sigma, 1, 3), 0.0);
  EXPECT_DOUBLE_EQ(solvers::departure_evidence(Eigen::Vector3d(0.05, -0.4, 0.0), sigma, 1, 3),
                   0.5);  // 2 sigmas of the second sensor
  EXPECT_EQ(solvers::departure_evidence(Eigen::Vector3d(0.05, -0.1, 0.5), sigma, 1, 3), 1.0);
  EXPECT_EQ(solvers::departure_evidence(Eigen::Vector3d(0.05, -0.1, nan), sigma, 1, 3), 0.0);
  EXPECT_EQ(solvers::departure_evidence(Eigen::Vector3d(0.35, 0, 0), sigma, 3, 3), 1.0);  // a step
  EXPECT_EQ(solvers::departure_evidence(Eigen::Vector3d(0.25, 0, 0), sigma, 3, 3), 0.0);
}

TEST_F(Observer, ExpansionSigmaIsEachMaterialsPartOfTheDrift) {
  // ObserverNoise::expansion_relative_sigma e: sigma^2 = sigma_0^2 + sum_m (e d_m)^2, d_m the
  // part of the drift material m's thermal strain makes. Checked against the full-order model:
  // truth runs (the generator on the case's own mesh) with one material's expansion coefficient
  // 10 % up move the drift by 0.1 d_m and no temperature; the observer reads the clean truth.
  const core::CaseSpec c = run_spec();
  const Eigen::MatrixXd clean = s_->clean_truth.displacement.leftCols(3);
  Eigen::MatrixXd sum_squares = Eigen::MatrixXd::Zero(clean.rows(), 3);
  for (std::size_t m = 0; m < s_->spec.materials.size(); ++m) {
    const calibration::InjectedEffect e{.present = true,
                                        .kind = calibration::EffectKind::material_parameter,
                                        .magnitude = 0.1,
                                        .target = s_->spec.materials[m].name + ".expansion"};
    const io::MeasuredRun run =
        calibration::clean_run(s_->mesh, calibration::truth_case(s_->gen, e, s_->duty, 2), e,
                               s_->inst, s_->g, "expansion");
    EXPECT_LT((run.temperature - s_->clean_truth.temperature).cwiseAbs().maxCoeff(), 1e-9);
    Eigen::MatrixXd part = (run.displacement.leftCols(3) - clean) / 0.1;
    part.rowwise() -= part.row(0);  // the drift: from t = 0
    sum_squares += part.cwiseAbs2();
  }
  const auto& sys = s_->twin.model.system;
  solvers::ObserverNoise wide = default_noise();
  wide.expansion_relative_sigma = Eigen::VectorXd::Constant(3, 0.2);  // three materials
  const solvers::ObserverRun plain =
      solvers::observe(sys, c, setup(default_noise()), s_->clean.time, s_->clean_truth.temperature);
  const solvers::ObserverRun with =
      solvers::observe(sys, c, setup(wide), s_->clean.time, s_->clean_truth.temperature);
  EXPECT_EQ(with.drift, plain.drift);
  ASSERT_EQ(with.times.size(), sum_squares.rows());
  const Eigen::ArrayXXd added = (with.drift_sigma.leftCols(3).array().square() -
                                 plain.drift_sigma.leftCols(3).array().square())
                                    .cwiseMax(0.0)
                                    .sqrt();
  const Eigen::ArrayXXd expected = 0.2 * sum_squares.array().sqrt();
  for (int d = 0; d < 3; ++d) {
    const double peak = expected.col(d).maxCoeff();
    std::cerr << "direction " << d << ": added sigma at the end "
              << added(added.rows() - 1, d) * 1e6 << " um, full order "
              << expected(expected.rows() - 1, d) * 1e6 << " um, peak " << peak * 1e6
              << " um, worst difference " << (added.col(d) - expected.col(d)).abs().maxCoeff() * 1e6
              << " um\n";
    if (d > 0) EXPECT_GT(peak, 0.5e-6) << "direction " << d;  // dx: the plane of symmetry
    EXPECT_LT((added.col(d) - expected.col(d)).abs().maxCoeff(), 1e-3 * peak + 1e-10)
        << "direction " << d;
  }
  // Without the rows per material (a model written before they were kept) it is refused.
  solvers::ObserverSetup old = setup(wide);
  old.target_expansion.clear();
  EXPECT_THROW(solvers::KalmanObserver(sys, c, old), core::SolverError);
  old = setup(wide);
  old.noise.expansion_relative_sigma = Eigen::VectorXd::Constant(3, -0.1);
  EXPECT_THROW(solvers::KalmanObserver(sys, c, old), core::SolverError);
  old.noise.expansion_relative_sigma = Eigen::VectorXd::Constant(2, 0.1);  // not one per material
  EXPECT_THROW(solvers::KalmanObserver(sys, c, old), core::SolverError);
  // One material's alone: its part only (the others' e 0).
  solvers::ObserverNoise one = default_noise();
  one.expansion_relative_sigma = Eigen::VectorXd::Zero(3);
  one.expansion_relative_sigma(0) = 0.2;
  const solvers::ObserverRun first =
      solvers::observe(sys, c, setup(one), s_->clean.time, s_->clean_truth.temperature);
  EXPECT_GT(first.drift_sigma(first.times.size() - 1, 2),
            plain.drift_sigma(plain.times.size() - 1, 2));
  EXPECT_LT(first.drift_sigma(first.times.size() - 1, 2),
            with.drift_sigma(with.times.size() - 1, 2));
}

/// The clean run with two readings missing (samples 5 and 40), the observer's run on all of it,
/// and what a live stream of it needs: its columns (the speed, an ignored one, the sensors in
/// reverse order: any order) and the declared case.
struct StreamedRun {
  io::MeasuredRun run;
  solvers::ObserverRun offline;
  std::vector<std::string> columns{"speed_rpm", "ignored"};
  core::CaseSpec declared;
  Eigen::Index speed = 0;  /// the run's input column of the speed
  /// The stream's values of sample i, the speed from sample `speed_from`'s.
  Eigen::VectorXd values(Eigen::Index i, Eigen::Index speed_from) const {
    const auto m = static_cast<Eigen::Index>(kSensors.size());
    Eigen::VectorXd v(2 + m);
    v(0) = run.input_values(speed_from, speed);
    v(1) = 1e9;
    for (Eigen::Index k = 0; k < m; ++k) v(2 + k) = run.temperature(i, m - 1 - k);
    return v;
  }
};

StreamedRun streamed_run(const io::MeasuredRun& clean, const core::CaseSpec& spec,
                         const solvers::Twin& twin, const solvers::ObserverSetup& set) {
  StreamedRun s;
  s.run = clean;
  s.run.temperature(5, 1) = std::numeric_limits<double>::quiet_NaN();
  s.run.temperature(40, 3) = std::numeric_limits<double>::quiet_NaN();
  const core::CaseSpec c = calibration::case_for_run(spec, s.run);
  s.offline = solvers::observe(twin.model.system, c, set, s.run.time, s.run.temperature);
  const auto speed = std::find(s.run.inputs.begin(), s.run.inputs.end(), "speed_rpm");
  EXPECT_NE(speed, s.run.inputs.end());
  s.speed = speed - s.run.inputs.begin();
  s.columns.insert(s.columns.end(), kSensors.rbegin(), kSensors.rend());
  s.declared = spec;
  if (s.run.initial_temperature_c)
    s.declared.thermal.initial_temperature_c = *s.run.initial_temperature_c;
  return s;
}

/// The largest difference of a live step's drift and sigma from the offline run's at sample i.
double step_gap(const core::LiveStep& step, const solvers::ObserverRun& offline, Eigen::Index i) {
  return std::max((step.predicted - offline.drift.row(i).transpose()).cwiseAbs().maxCoeff(),
                  (step.sigma - offline.drift_sigma.row(i).transpose()).cwiseAbs().maxCoeff());
}

TEST_F(Observer, AStreamThroughTheLiveObserverIsTheRecordedRun) {
  // The run sample by sample, its speed column read as it comes and two readings missing, gives
  // what the observer gives on the whole recorded run (its duty cycle from the same column).
  const solvers::ObserverSetup set = setup(default_noise());
  const StreamedRun s = streamed_run(s_->clean, s_->spec, s_->twin, set);
  // A filter period shorter than the samples' spacing: one sample per period.
  solvers::LiveObserver live(s_->twin.model.system, s.declared, set, kSensors, s.columns,
                             "speed_rpm", {.filter_every_s = 1.0});
  double worst = 0;
  for (Eigen::Index i = 0; i < s.run.time.size(); ++i) {
    const core::LiveStep& step = live.next(s.run.time(i), s.values(i, i));
    ASSERT_EQ(step.status, (i == 5 || i == 40) ? core::SampleStatus::held : core::SampleStatus::ok)
        << "sample " << i;
    worst = std::max(worst, step_gap(step, s.offline, i));
  }
  EXPECT_LE(worst, 1e-12 * s.offline.drift.cwiseAbs().maxCoeff());
  EXPECT_EQ(live.assimilations(), s.run.time.size());
  EXPECT_EQ(live.next(s.run.time(3), s.values(3, 3)).status, core::SampleStatus::late);
  EXPECT_THROW(solvers::LiveObserver(s_->twin.model.system, s.declared, set, kSensors,
                                     {"speed_rpm", "T02"}, "speed_rpm"),
               core::DataError);
}

TEST_F(Observer, AStreamOnAClocksTimeStartsAtItsFirstSampleWhenAsked) {
  // The run's times on a clock (Unix time): read as the time since the model's start, the first
  // sample would be 54 years in, refused naming its time; with from_first_sample the first sample
  // is t = 0 and the stream gives the recorded run.
  const solvers::ObserverSetup set = setup(default_noise());
  const StreamedRun s = streamed_run(s_->clean, s_->spec, s_->twin, set);
  const double clock = 1.7e9;
  solvers::LiveObserver since_start(s_->twin.model.system, s.declared, set, kSensors, s.columns,
                                    "speed_rpm");
  try {
    since_start.next(clock + s.run.time(0), s.values(0, 0));
    ADD_FAILURE() << "a first sample at a clock's time was marched to";
  } catch (const core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("the first sample is at time_s = 1700000000"),
              std::string::npos)
        << e.what();
  }
  // A recorded run on a clock's time: refused where its duty cycle is read (observe, calibrate),
  // naming its data.csv and the time.
  io::MeasuredRun on_clock = s.run;
  on_clock.time.array() += clock;
  try {
    calibration::case_for_run(s_->spec, on_clock);
    ADD_FAILURE() << "a recorded run on a clock's time was read";
  } catch (const core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("data.csv): the first sample is at time_s = 1700000000"),
              std::string::npos)
        << e.what();
  }
  solvers::LiveObserver live(s_->twin.model.system, s.declared, set, kSensors, s.columns,
                             "speed_rpm", {.from_first_sample = true});
  ASSERT_EQ(s.run.time(0), 0);
  double worst = 0;
  for (Eigen::Index i = 0; i < s.run.time.size(); ++i)
    worst =
        std::max(worst, step_gap(live.next(clock + s.run.time(i), s.values(i, i)), s.offline, i));
  EXPECT_LE(worst, 1e-12 * s.offline.drift.cwiseAbs().maxCoeff());
}

TEST_F(Observer, ADenseStreamIsAssimilatedOncePerFilterPeriod) {
  // Five samples per recorded interval, the filter period the interval: four inside it carry the
  // interval's closing reading and the speed held over it, the fifth (at the recorded time) the
  // recorded sample. Each period's mean is then the recorded reading and its time-mean speed the
  // held one, so the live observer assimilates once per period and gives the recorded run's
  // estimates at the recorded times, holding the last one between them.
  const solvers::ObserverSetup set = setup(default_noise());
  const StreamedRun s = streamed_run(s_->clean, s_->spec, s_->twin, set);
  const double spacing = s.run.time(1) - s.run.time(0);
  ASSERT_GT(spacing, 0);
  for (Eigen::Index i = 2; i < s.run.time.size(); ++i)
    ASSERT_NEAR(s.run.time(i) - s.run.time(i - 1), spacing, 1e-9) << "sample " << i;
  solvers::LiveObserver live(s_->twin.model.system, s.declared, set, kSensors, s.columns,
                             "speed_rpm", {.filter_every_s = spacing});
  double worst = 0;
  long long samples = 0;
  for (Eigen::Index i = 0; i < s.run.time.size(); ++i) {
    const bool missing = i == 5 || i == 40;
    for (int k = 1; i > 0 && k < 5; ++k, ++samples) {
      const core::LiveStep& between =
          live.next(s.run.time(i - 1) + k * spacing / 5, s.values(i, i - 1));
      ASSERT_EQ(between.status, missing ? core::SampleStatus::held : core::SampleStatus::ok);
      worst = std::max(worst, step_gap(between, s.offline, i - 1));
    }
    const core::LiveStep& step = live.next(s.run.time(i), s.values(i, i));
    ++samples;
    ASSERT_EQ(step.status, missing ? core::SampleStatus::held : core::SampleStatus::ok);
    worst = std::max(worst, step_gap(step, s.offline, i));
  }
  EXPECT_LE(worst, 1e-12 * s.offline.drift.cwiseAbs().maxCoeff());
  EXPECT_EQ(live.assimilations(), s.run.time.size());
  EXPECT_EQ(samples, 5 * s.run.time.size() - 4);
}

TEST_F(Observer, PosteriorVarianceIsKnownBeforeTheReadingsAndPlacementLowersIt) {
  // The covariance does not see the readings' values: two runs far apart report the same sigma,
  // so the criterion of a sensor set can be computed before any sensor reads.
  core::CaseSpec c = run_spec();
  c.duty_cycle.end = 3600;
  const solvers::ObserverSetup set = setup(default_noise());
  Eigen::VectorXd times = Eigen::VectorXd::LinSpaced(6, 600, 3600);
  const auto k = static_cast<Eigen::Index>(kSensors.size());
  const solvers::ObserverRun cool = solvers::observe(s_->twin.model.system, c, set, times,
                                                     Eigen::MatrixXd::Constant(6, k, 293.0));
  const solvers::ObserverRun hot = solvers::observe(s_->twin.model.system, c, set, times,
                                                    Eigen::MatrixXd::Constant(6, k, 320.0));
  EXPECT_LE((cool.drift_sigma - hot.drift_sigma).cwiseAbs().maxCoeff(),
            1e-9 * cool.drift_sigma.maxCoeff());
  // The covariance model as placement takes it (studies::observer_estimation_problem: the map
  // from each reading to the next, KalmanObserver::advance) gives the observer's own variance.
  std::vector<std::string> candidates;
  for (int i = 0; i < s_->twin.outputs.temperatures; ++i)
    if (const std::string& n = s_->twin.outputs.names[static_cast<std::size_t>(i)];
        n.size() == 3 && n[0] == 'T' && std::isdigit(static_cast<unsigned char>(n[1])))
      candidates.push_back(n);  // T01..T54, not the TCP
  ASSERT_GE(candidates.size(), 20u);
  const placement::EstimationProblem problem = studies::observer_estimation_problem(
      s_->twin, {c}, {candidates, {}, 0.04}, {"dx", "dy", "dz"}, default_noise(), 600);
  std::vector<int> hand;
  for (const auto& id : kSensors)
    hand.push_back(
        static_cast<int>(std::find(candidates.begin(), candidates.end(), id) - candidates.begin()));
  const Eigen::VectorXd v = placement::mean_posterior_variance(problem, hand);
  for (int t = 0; t < 3; ++t)
    EXPECT_NEAR(v(t), cool.drift_sigma.col(t).array().square().mean(), 1e-9 * v(t)) << t;

  // Greedy placement for estimation of dy and dz among every named T point: each sensor added
  // lowers the posterior variance, the reported figure is the set's criterion, and three placed
  // sensors estimate better than the first three of the hand-picked set.
  std::vector<int> pool(candidates.size());
  for (std::size_t k = 0; k < pool.size(); ++k) pool[k] = static_cast<int>(k);
  const std::vector<int> dy_dz{1, 2};
  const placement::GreedyPath placed = placement::estimation_greedy(problem, pool, 3, dy_dz);
  ASSERT_EQ(placed.order.size(), 3u);
  EXPECT_LT(placed.scores[1], placed.scores[0]);
  EXPECT_LT(placed.scores[2], placed.scores[1]);
  const auto criterion = [&](const std::vector<int>& sensors) {
    const Eigen::VectorXd var = placement::mean_posterior_variance(problem, sensors);
    return var(1) + var(2);
  };
  EXPECT_NEAR(criterion(placed.order), placed.scores[2], 1e-10 * placed.scores[2]);
  const double first3 = criterion({hand[0], hand[1], hand[2]});
  EXPECT_LT(placed.scores[2], first3);
  const auto name = [&](int k) { return candidates[static_cast<std::size_t>(placed.order[k])]; };
  std::printf(
      "[observer] placed for estimation: %s %s %s, sigma(dy+dz) %.3g um (hand-picked %s "
      "%s %s: %.3g um)\n",
      name(0).c_str(), name(1).c_str(), name(2).c_str(), std::sqrt(placed.scores[2]) * 1e6,
      kSensors[0].c_str(), kSensors[1].c_str(), kSensors[2].c_str(), std::sqrt(first3) * 1e6);
  EXPECT_THROW(studies::observer_estimation_problem(s_->twin, {c}, {{"T02", "nowhere"}, {}, 0.04},
                                                    {"dy"}, default_noise(), 600),
               core::SolverError);
  EXPECT_THROW(studies::observer_estimation_problem(s_->twin, {c}, {{"T02"}, {}, 0.04}, {"dq"},
                                                    default_noise(), 600),
               core::SolverError);
}

TEST_F(Observer, DetectionPlacementReadsTheChangeAnUndeclaredAirMakes) {
  // Placement for detection (studies::observer_detection_problem): the change the observer's
  // air input makes at each candidate, carried by the filter's maps, against the twin run twice,
  // with the declared air and with every air sink 1 K warmer; held over 900 s of readings every
  // 300 s (four readings), in the candidates' sigmas.
  core::CaseSpec c = run_spec();
  c.duty_cycle.end = 3 * 3600;
  c.thermal.output_interval = 300;
  const std::vector<std::string> candidates{"T02", "T11", "T25", "T44"};
  const placement::EstimationProblem problem = studies::observer_estimation_problem(
      s_->twin, {c}, {candidates, {}, 0.04}, {"dy", "dz"}, default_noise(), 300);
  const placement::DetectionProblem d =
      studies::observer_detection_problem(s_->twin, problem, c, default_noise(), {5, 1}, 900, 300);
  const auto air = std::find(d.effects.begin(), d.effects.end(), "air");
  ASSERT_NE(air, d.effects.end());
  for (const auto& e : d.effects) EXPECT_EQ(e.rfind("offset:", 0), std::string::npos) << e;
  EXPECT_EQ(static_cast<std::size_t>(d.held_sigmas.rows()), d.effects.size());
  const auto [helds, times] = held_air_change(c, solvers::air_entries(c), candidates);
  ASSERT_EQ(times, 37u);  // t = 0, then every 300 s for 3 h
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const double held = helds[k];
    EXPECT_NEAR(d.held_sigmas(air - d.effects.begin(), static_cast<Eigen::Index>(k)), held,
                1e-6 * held)
        << candidates[k];
    EXPECT_GT(held, 3.0) << candidates[k];  // 1 K of air shows at every sensor of SB-1
  }
  EXPECT_THROW(
      studies::observer_detection_problem(s_->twin, problem, c, default_noise(), {5, 1}, 0, 300),
      core::SolverError);
}

TEST_F(Observer, CatalogueDetectionReadsEachEffectAsTheFullModelAndTheTwinDo) {
  // Placement for detection on the calibration catalogue's effects
  // (studies::catalogue_detection), marched on the reduced model on the candidates' rows:
  // every effect's held change as the full-order march gives it, and the air's 1 K on every sink
  // as the twin run twice gives it (with the declared air; with every sink 1 K warmer); held over
  // 900 s of readings every 300 s (four readings), in the candidates' sigmas.
  core::CaseSpec c = run_spec();
  c.duty_cycle.end = 2 * 3600;
  c.thermal.output_interval = 300;
  studies::CatalogueDetectionInput in;
  in.names = {"T02", "T11", "T25", "T44"};
  for (const auto& name : in.names)
    for (const auto& p : s_->mesh.points)
      if (p.id == name) in.points.push_back(p.position);
  ASSERT_EQ(in.points.size(), in.names.size());
  in.sensor_sigma_k = 0.04;
  in.catalogue.patch_spacing = 0.15;
  in.catalogue.patch_half_size = 0.1;
  in.catalogue.heat_laws = {calibration::HeatLaw::constant};
  const studies::CatalogueDetection detection =
      studies::catalogue_detection(s_->mesh, s_->spec, {c}, in);
  const placement::DetectionProblem& d = detection.problem;
  in.full_order = true;
  const placement::DetectionProblem full =
      studies::catalogue_detection(s_->mesh, s_->spec, {c}, in).problem;
  ASSERT_EQ(detection.effects.size(), d.effects.size());
  ASSERT_EQ(detection.sizes.size(), static_cast<Eigen::Index>(d.effects.size()));
  for (std::size_t e = 0; e < detection.effects.size(); ++e)
    if (const auto* h = std::get_if<calibration::HeatInput>(&detection.effects[e]))
      EXPECT_NEAR(detection.sizes(static_cast<Eigen::Index>(e)) * h->area, 5.0, 1e-12);  // W
  ASSERT_EQ(d.effects, full.effects);
  ASSERT_EQ(d.held_sigmas.rows(), static_cast<Eigen::Index>(d.effects.size()));
  ASSERT_EQ(d.held_sigmas.cols(), 4);
  int patches = 0;
  for (const auto& e : d.effects) patches += e.find("heat input") != std::string::npos;
  EXPECT_GT(patches, 10);
  for (const std::string kind :
       {"conductance of", "growing with speed", "growing with its temperature", "conductivity of",
        "heat_capacity of", "air temperature on every convective sink"})
    EXPECT_TRUE(std::any_of(d.effects.begin(), d.effects.end(), [&](const std::string& e) {
      return e.find(kind) != std::string::npos;
    })) << kind;
  for (Eigen::Index e = 0; e < d.held_sigmas.rows(); ++e)
    for (Eigen::Index k = 0; k < 4; ++k)
      EXPECT_NEAR(d.held_sigmas(e, k), full.held_sigmas(e, k),
                  1e-4 * full.held_sigmas.row(e).maxCoeff())
          << d.effects[static_cast<std::size_t>(e)] << " at "
          << in.names[static_cast<std::size_t>(k)];
  double worst = 0;  // the largest difference, relative to the effect's largest held change
  for (Eigen::Index e = 0; e < d.held_sigmas.rows(); ++e)
    worst = std::max(worst, (d.held_sigmas.row(e) - full.held_sigmas.row(e)).cwiseAbs().maxCoeff() /
                                full.held_sigmas.row(e).maxCoeff());
  std::printf(
      "[observer] catalogue detection: %zu effects (%d patches), reduced against full "
      "order: largest difference %.2g of the effect's largest held change; held [sigma] "
      "range %.3g .. %.3g\n",
      d.effects.size(), patches, worst, d.held_sigmas.minCoeff(), d.held_sigmas.maxCoeff());
  // Some patch is seen (3 sigma) by some candidate and not by another: the criterion has a choice.
  const double bound = 3;
  EXPECT_TRUE(((d.held_sigmas.array() >= bound).rowwise().any() &&
               (d.held_sigmas.array() < bound).rowwise().any())
                  .any());
  const auto air =
      std::find(d.effects.begin(), d.effects.end(), "air temperature on every convective sink");
  ASSERT_NE(air, d.effects.end());
  std::vector<int> every_sink(c.thermal.convection.size());
  for (std::size_t k = 0; k < every_sink.size(); ++k) every_sink[k] = static_cast<int>(k);
  const auto [helds, times] = held_air_change(c, every_sink, in.names);
  ASSERT_EQ(times, 25u);  // t = 0, then every 300 s for 2 h
  for (std::size_t k = 0; k < in.names.size(); ++k) {
    const double held = helds[k];
    EXPECT_NEAR(d.held_sigmas(air - d.effects.begin(), static_cast<Eigen::Index>(k)), held,
                0.01 * held)
        << in.names[k];
  }
  in.sustain_s = 0;
  EXPECT_THROW(studies::catalogue_detection(s_->mesh, s_->spec, {c}, in), core::DataError);
}

TEST(ObserverPieces, ChiSquareQuantileAndMonitor) {
  // Tabulated quantiles: chi2(0.999; 10) = 29.59, chi2(0.999; 100) = 149.45, chi2(0.95; 30)
  // = 43.77.
  EXPECT_NEAR(solvers::chi_square_quantile(0.999, 10), 29.59, 0.3);
  EXPECT_NEAR(solvers::chi_square_quantile(0.999, 100), 149.45, 0.5);
  EXPECT_NEAR(solvers::chi_square_quantile(0.95, 30), 43.77, 0.2);
  // NIS at its expectation never alarms; four times it, held past window and sustain, does.
  solvers::ConsistencyOptions o;
  o.window_s = 600;
  o.sustain_s = 300;
  solvers::InnovationMonitor quiet(o), loud(o);
  for (int k = 0; k <= 120; ++k) {
    EXPECT_FALSE(quiet.add(60.0 * k, 5.0, 5));
    loud.add(60.0 * k, k < 30 ? 5.0 : 20.0, 5);
  }
  EXPECT_TRUE(loud.recalibrate());
  EXPECT_NEAR(loud.since_s(), 1800.0, 60.0);  // the change point, not the window's end
}

/// One raised sensor: which, since when and when raised [s].
void expect_held(const solvers::HeldSensor& h, int sensor, double since_s, double raised_s) {
  EXPECT_EQ(h.sensor, sensor);
  EXPECT_DOUBLE_EQ(h.since_s, since_s);
  EXPECT_DOUBLE_EQ(h.raised_s, raised_s);
}

TEST(ObserverPieces, HeldBeyondMonitor) {
  // Sensor 1 goes beyond 4 sigma at t = 600 s and stays: raised once at 600 + 300 s. Sensor 0
  // crosses for less than the sustain time, alone (180 s): not raised; then from 1200 s, beside
  // the faulty sensor 1, for good: raised at 1500 s. Sensor 2 stays within.
  solvers::HeldBeyondMonitor m(4, 300);
  for (int k = 0; k <= 30; ++k) {
    const double t = 60.0 * k;
    const bool beyond = (k >= 3 && k <= 6) || k >= 20;
    m.add(t, Eigen::Vector3d(beyond ? -0.5 : 0.1, k >= 10 ? 0.45 : 0.0, 0.39),
          Eigen::Vector3d(0.1, 0.1, 0.1));
  }
  ASSERT_EQ(m.raised().size(), 2u);
  expect_held(m.raised()[0], 1, 600.0, 900.0);
  EXPECT_EQ(m.raised()[1].sensor, 0);
  EXPECT_DOUBLE_EQ(m.raised()[1].raised_s, 1500.0);
  // Two sensors beyond together, neither faulty yet: heat or air, not two faults. One of them
  // alone again afterwards: raised a sustain time after it is alone.
  solvers::HeldBeyondMonitor pair(4, 300);
  for (int k = 0; k <= 30; ++k)
    pair.add(60.0 * k, Eigen::Vector3d(0.5, k < 20 ? 0.5 : 0.0, 0.0),
             Eigen::Vector3d::Constant(0.1));
  ASSERT_EQ(pair.raised().size(), 1u);
  expect_held(pair.raised()[0], 0, 1200.0, 1500.0);
  // A bound of 0: no test.
  solvers::HeldBeyondMonitor off(0, 300);
  for (int k = 0; k <= 30; ++k)
    off.add(60.0 * k, Eigen::Vector3d(9, 9, 9), Eigen::Vector3d::Ones());
  EXPECT_TRUE(off.raised().empty());
  // Not exclusive (the readings against the declared model): two sensors beyond together are
  // both raised, each a sustain time after it crossed; NaN (a missing or left-out reading) is
  // not beyond and restarts the clock.
  solvers::HeldBeyondMonitor both(3, 300, false);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int k = 0; k <= 30; ++k)
    both.add(60.0 * k, Eigen::Vector3d(0.5, k == 12 ? nan : (k >= 8 ? -0.5 : 0.0), 0.29),
             Eigen::Vector3d::Constant(0.1));
  ASSERT_EQ(both.raised().size(), 2u);
  expect_held(both.raised()[0], 0, 0.0, 300.0);
  expect_held(both.raised()[1], 1, 780.0, 1080.0);
  EXPECT_DOUBLE_EQ(both.raised()[1].onset_s, 780.0);  // no onset bound: the crossing
  // An onset bound of 1 sigma. Sensor 0 grows by 0.1 sigma a sample from 600 s: within 1 sigma
  // last at 1140 s, beyond 3 sigma from 2400 s, raised at 2700 s with its onset at 1140 s.
  // Sensor 1 is beyond 1 sigma from the first sample and beyond 3 from 300 s: its onset is the
  // first sample. Sensor 2 jumps beyond 3 sigma at 600 s and comes back after it was raised:
  // its onset stays the last sample before the jump.
  solvers::HeldBeyondMonitor onset(3, 300, false, 1);
  for (int k = 0; k <= 60; ++k)
    onset.add(60.0 * k,
              Eigen::Vector3d(k >= 10 ? 0.1 * (k - 10) + 0.05 : 0.0, k >= 5 ? 4.0 : 2.0,
                              k >= 10 && k <= 30 ? 5.0 : 0.0),
              Eigen::Vector3d::Ones());
  ASSERT_EQ(onset.raised().size(), 3u);
  expect_held(onset.raised()[0], 1, 300.0, 600.0);
  EXPECT_DOUBLE_EQ(onset.raised()[0].onset_s, 0.0);
  expect_held(onset.raised()[1], 2, 600.0, 900.0);
  EXPECT_DOUBLE_EQ(onset.raised()[1].onset_s, 540.0);
  expect_held(onset.raised()[2], 0, 2400.0, 2700.0);
  EXPECT_DOUBLE_EQ(onset.raised()[2].onset_s, 1140.0);
}

}  // namespace
}  // namespace tt::observer_test
