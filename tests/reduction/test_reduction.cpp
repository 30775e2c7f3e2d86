// The reduced-order model (solvers/reduction): a C-orthonormal basis that holds the uniform field,
// stable reduced steps for any film, and reduced runs that follow the full model within 0.01 K at
// every node on duty cycles the basis was not built from: a speed-dependent film, a time-varying
// sink, a temperature-dependent source, and heat that moves with a feed axis. The error indicator
// is small on a good basis and large on a truncated one; a model built for another case is
// refused.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/cholmod/cholmod_factor.hpp"
#include "solvers/feed_axis.hpp"
#include "solvers/loads.hpp"
#include "solvers/reduction.hpp"
#include "solvers/thermal.hpp"
#include "solvers/thermal_stepper.hpp"
#include "tests/common/case_toml.hpp"
#include "tests/common/gantry_bar.hpp"

namespace tt::reduction_test {
namespace {

using core::kCelsiusOffset;

/// A block with a bearing pad (speed-power source whose heat grows with its temperature), a top
/// film that follows the speed, a bottom film whose sink temperature varies, and still air
/// elsewhere. `segments` is the duty cycle; its end is `end` [s].
std::string block_case(const std::string& segments, double end, const std::string& sink_table) {
  std::string t = test_toml::header("reduction block") + test_toml::steel();
  t += test_toml::box_body("block", "steel", "0.03", "[0.0, 0.0, 0.0]", "[0.2, 0.1, 0.08]");
  t += test_toml::box_body("pad", "steel", "0.02", "[0.2, 0.0, 0.0]", "[0.24, 0.1, 0.08]");
  t += "[mesh]\norder = 1\n[mechanical]\nenabled = false\n";
  t += "[[boundary]]\nname = \"top\"\nselect = [ { bodies = [\"block\", \"pad\"], plane = { "
       "normal = [0.0, 1.0, 0.0], offset = 0.1 } } ]\n";
  t += "[[boundary]]\nname = \"bottom\"\nselect = [ { bodies = [\"block\"], plane = { "
       "normal = [0.0, 1.0, 0.0], offset = 0.0 } } ]\n";
  t += "[[boundary]]\nname = \"rest\"\nrest = true\nselect = [ { bodies = [\"block\", \"pad\"] "
       "} ]\n";
  t += "[thermal]\ninitial_temperature_degC = 20.0\nstep_s = 12.0\noutput_interval_s = 120.0\n";
  t += "[[thermal.convection]]\ngroup = \"top\"\nh_W_m2K = 8.0\nh_speed_gain_W_m2K = 30.0\n"
       "speed_ref_rpm = 3000.0\nspeed_exponent = 0.8\nsink_degC = 20.0\n";
  t += "[[thermal.convection]]\ngroup = \"bottom\"\nh_W_m2K = 60.0\nsink_table = " + sink_table +
       "\n";
  t += "[[thermal.convection]]\ngroup = \"rest\"\nh_W_m2K = 5.0\nsink_degC = 20.0\n";
  t += "[[thermal.heat_sources]]\nname = \"bearing\"\nbody = \"pad\"\nlaw = \"speed_power\"\n"
       "power_ref_W = 40.0\nref_speed_rpm = 3000.0\nexponent = 1.2\n"
       "temperature_coefficient_per_K = 0.02\n";
  t += "[[thermal.heat_sources]]\nname = \"motor\"\nbody = \"block\"\nlaw = \"constant\"\n"
       "power_ref_W = 3.0\n";
  t += "[duty_cycle]\nend_s = " + std::to_string(end) + "\nsegments = " + segments + "\n";
  return t;
}

core::CaseSpec spec_of(const std::string& toml) {
  return io::case_from_toml(toml, std::string(TT_BINARY_DIR) + "/reduction_test.toml");
}

/// P-1-like: what the basis's speeds are chosen for (0 and 6000 rpm), not stepped.
const char* kSteadySink = "[[0.0, 20.0]]";
/// A staircase 1000 .. 6000 .. 0 rpm, 15 min each, under a bottom sink that swings by 4 K.
const char* kStaircase =
    "[ { start_s = 0.0, speed_rpm = 1000.0 }, { start_s = 900.0, speed_rpm = 2000.0 }, "
    "{ start_s = 1800.0, speed_rpm = 4000.0 }, { start_s = 2700.0, speed_rpm = 6000.0 }, "
    "{ start_s = 3600.0, speed_rpm = 3000.0 }, { start_s = 4500.0, speed_rpm = 0.0 } ]";
const char* kSwingingSink = "[[0.0, 20.0], [1500.0, 24.0], [3000.0, 18.0], [5400.0, 21.0]]";

struct ReducedRun {
  Eigen::MatrixXd temperature;                /// #nodes x #output times (t = 0 first) [K]
  std::vector<solvers::ReducedStep> samples;  /// the steps that end at an output time
};

/// The reduced system stepped by the one stepper (backward Euler), its states recorded at the
/// output times and at the step end before each, and every step that ends at an output time
/// sampled for the indicator.
ReducedRun reduced_run(const solvers::FullThermalSystem& full, const solvers::ReducedModel& model,
                       const core::CaseSpec& spec) {
  const std::vector<double> grid = solvers::time_grid(spec, spec.thermal.step);
  const std::vector<double> outs = solvers::output_times(spec);
  const std::vector<double> switches = solvers::switch_times(spec);
  solvers::StepperRequest q;
  std::vector<size_t> sampled;  // grid indices of the steps that end at an output time
  for (size_t i = 0; i < grid.size(); ++i) {
    if (std::find(outs.begin(), outs.end(), grid[i]) == outs.end()) continue;
    sampled.push_back(i);
    if (i > 0) q.record_times.push_back(grid[i - 1]);
    q.record_times.push_back(grid[i]);
  }
  for (double t : outs) q.record_times.push_back(t);
  std::sort(q.record_times.begin(), q.record_times.end());
  q.record_times.erase(std::unique(q.record_times.begin(), q.record_times.end()),
                       q.record_times.end());
  const solvers::SteppedHistory h = solvers::step_thermal(model.system, spec, q);
  const auto state_at = [&](double t) -> Eigen::VectorXd {
    if (t == 0) return h.states.col(0);
    const auto it = std::find(h.times.begin(), h.times.end(), t);
    EXPECT_NE(it, h.times.end()) << "no recorded state at t = " << t;
    return h.states.col(it - h.times.begin());
  };
  ReducedRun run;
  Eigen::MatrixXd z_out(model.states(), static_cast<Eigen::Index>(outs.size() + 1));
  z_out.col(0) = h.states.col(0);
  for (size_t j = 0; j < outs.size(); ++j)
    z_out.col(static_cast<Eigen::Index>(j + 1)) = state_at(outs[j]);
  run.temperature = model.basis * z_out;
  for (size_t i : sampled) {
    solvers::ReducedStep s;
    const double t_prev = i > 0 ? grid[i - 1] : 0.0, t = grid[i];
    s.dt = t - t_prev;
    s.state_old = state_at(t_prev);
    s.state_new = state_at(t);
    solvers::StepLoad load = solvers::step_load(full, spec, t_prev, t, model.basis * s.state_old);
    s.load = std::move(load.load);
    s.film = std::move(load.film);
    double last_switch = 0;
    for (double w : switches)
      if (w < t) last_switch = w;
    s.horizon = t - last_switch;
    run.samples.push_back(std::move(s));
  }
  return run;
}

/// Largest |reduced - full| over every node and output time [K].
double max_difference(const Eigen::MatrixXd& reduced, const solvers::ThermalHistory& full) {
  EXPECT_EQ(reduced.rows(), full.temperature.rows());
  EXPECT_EQ(reduced.cols(), full.temperature.cols());
  return (reduced - full.temperature).cwiseAbs().maxCoeff();
}

/// Largest temperature rise over the run [K], so that a comparison is known not to be trivial.
double max_rise(const solvers::ThermalHistory& full) {
  return (full.temperature.array() - full.temperature(0, 0)).abs().maxCoeff();
}

struct Block {
  core::CaseSpec spec;
  mesh::TetMesh mesh;
  solvers::FullThermalSystem full;
  solvers::ReducedModel model;
};

/// The block meshed once, with the basis built for speeds 0 and 6000 rpm (no duty cycle).
const Block& block() {
  static const Block b = [] {
    Block x;
    x.spec = spec_of(block_case("[ { start_s = 0.0, speed_rpm = 3000.0 } ]", 7200.0, kSteadySink));
    x.mesh = mesh::mesh_case(x.spec);
    x.full = solvers::thermal_system(x.mesh, x.spec);
    solvers::ReductionOptions o;
    o.speeds_rpm = {0.0, 6000.0};
    x.model = solvers::reduced_model(x.full, x.spec, o);
    std::printf(
        "[reduction] block: %d nodes, %d states, %d inputs, %d candidates, %d deflated, "
        "%d factors, %.3f s\n",
        static_cast<int>(x.full.states()), x.model.states(), x.model.stats.input_columns,
        x.model.stats.candidate_columns, x.model.stats.deflated_columns,
        x.model.stats.factorizations, x.model.stats.build_s);
    return x;
  }();
  return b;
}

TEST(ReductionBasis, IsCapacityOrthonormalAndHoldsTheUniformField) {
  const Block& b = block();
  const Eigen::MatrixXd& v = b.model.basis;
  const Eigen::Index r = v.cols();
  ASSERT_GT(r, 10);
  EXPECT_LT(r, b.full.states() / 2);
  const Eigen::MatrixXd gram = v.transpose() * (b.full.capacity * v);
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(r, r)).cwiseAbs().maxCoeff(), 1e-10);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(b.full.states());
  EXPECT_LT((v * b.model.system.uniform - ones).cwiseAbs().maxCoeff(), 1e-10);
  // Every projected operator is symmetric, the vectors are V^T b.
  EXPECT_LT((b.model.system.conduction - b.model.system.conduction.transpose()).norm(), 1e-12);
  EXPECT_NEAR(b.model.system.film_area[1].dot(b.model.system.uniform), b.full.film_area[1].sum(),
              1e-10 * b.full.film_area[1].sum());
  // A film state that removes heat: 0 is among the shifts, and 2 states were sampled.
  EXPECT_EQ(b.model.stats.film_states.size(), 2u);
  EXPECT_EQ(b.model.stats.shifts_per_s.front(), 0.0);
}

TEST(ReductionBasis, DoesNotDependOnTheThreadCount) {
  // The shifts are factored two at a time, side by side; the columns join in a fixed order.
  const Block& b = block();
  solvers::ReductionOptions o;
  o.speeds_rpm = {0.0, 6000.0};
  omp_set_num_threads(1);
  const Eigen::MatrixXd one = solvers::reduction_basis(b.full, b.spec, o);
  omp_set_num_threads(2);
  const Eigen::MatrixXd two = solvers::reduction_basis(b.full, b.spec, o);
  ASSERT_EQ(one.cols(), b.model.basis.cols());
  ASSERT_EQ(two.cols(), one.cols());
  EXPECT_EQ((one - two).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Factor, SharesOneAnalysisAndRefusesAnotherPattern) {
  const Block& b = block();
  Eigen::SparseMatrix<double> a = b.full.conduction + 1e-3 * b.full.capacity;
  a.makeCompressed();
  const solvers::cholmod::Analysis analysis(a, "pattern");
  Eigen::SparseMatrix<double> a2 = b.full.conduction + 2e-3 * b.full.capacity;
  a2.makeCompressed();
  const Eigen::VectorXd rhs = b.full.capacity * Eigen::VectorXd::LinSpaced(a.rows(), 0, 1);
  const Eigen::MatrixXd shared = solvers::cholmod::Factor(analysis, a2, "shared").solve(rhs);
  const Eigen::MatrixXd own = solvers::cholmod::Factor(a2, "own").solve(rhs);
  EXPECT_LT((shared - own).cwiseAbs().maxCoeff(), 1e-12 * own.cwiseAbs().maxCoeff());
  Eigen::SparseMatrix<double> diag(a.rows(), a.cols());
  diag.setIdentity();
  diag.makeCompressed();
  try {
    solvers::cholmod::Factor(analysis, diag, "diagonal");
    ADD_FAILURE() << "another pattern was accepted";
  } catch (const tt::core::SolverError& e) {
    EXPECT_NE(std::string(e.what()).find("is not the analysed one"), std::string::npos) << e.what();
  }
}

TEST(ReductionBasis, ReducedStepsAreStableForAnyFilm) {
  const auto& sys = block().model.system;
  const Eigen::Index r = sys.capacity.rows();
  for (double scale : {0.0, 1.0, 100.0}) {
    Eigen::MatrixXd k = sys.conduction;
    for (const auto& f : sys.film) k += (60.0 * scale) * f;
    // K(h) symmetric positive semi-definite relative to the capacity (= I).
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(k, sys.capacity);
    ASSERT_EQ(eig.info(), Eigen::Success);
    EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-9 * eig.eigenvalues().maxCoeff()) << scale;
    for (double dt : {1.0, 12.0, 3600.0}) {
      // Backward Euler (C + dt K)^{-1} C and Crank-Nicolson (C + dt/2 K)^{-1} (C - dt/2 K).
      const Eigen::MatrixXd be = (sys.capacity + dt * k).llt().solve(sys.capacity);
      const Eigen::MatrixXd cn =
          (sys.capacity + 0.5 * dt * k).llt().solve(sys.capacity - 0.5 * dt * k);
      const double rho_be = be.eigenvalues().cwiseAbs().maxCoeff();
      const double rho_cn = cn.eigenvalues().cwiseAbs().maxCoeff();
      EXPECT_LE(rho_be, 1 + 1e-9) << "h scale " << scale << ", dt " << dt;
      EXPECT_LE(rho_cn, 1 + 1e-9) << "h scale " << scale << ", dt " << dt;
      if (scale > 0) {
        EXPECT_LT(rho_be, 1.0) << "a film removes heat: strictly contracting";
      }
    }
  }
  (void)r;
}

/// The staircase under a swinging sink, on the block's basis: every node within 0.01 K.
TEST(ReducedRun, FollowsTheFullModelOnAStaircaseItWasNotBuiltFrom) {
  const Block& b = block();
  const core::CaseSpec spec = spec_of(block_case(kStaircase, 5400.0, kSwingingSink));
  solvers::check_reducible(b.model, b.full, spec);
  const solvers::ThermalHistory full = solvers::thermal_history(b.mesh, spec, b.full);
  const ReducedRun red = reduced_run(b.full, b.model, spec);
  const double diff = max_difference(red.temperature, full);
  const auto ind = solvers::error_indicator(b.full, b.model, red.samples);
  std::printf("[reduction] staircase: rise %.3f K, max |reduced - full| %.2e K, indicator %.2e K\n",
              max_rise(full), diff, ind.max_k);
  EXPECT_GT(max_rise(full), 5.0);
  EXPECT_LT(diff, 0.01);
  EXPECT_FALSE(ind.above_tolerance());
  // An estimate, not a bound: within a factor 3 of the real error either way.
  EXPECT_GT(ind.max_k, diff / 3);
  EXPECT_LT(ind.max_k, diff * 3);
}

/// The same staircase with Crank-Nicolson: the stepper's reduced steps follow the full ones too.
TEST(ReducedRun, FollowsTheFullModelWithCrankNicolson) {
  const Block& b = block();
  core::CaseSpec spec = spec_of(block_case(kStaircase, 5400.0, kSwingingSink));
  spec.thermal.scheme = core::TimeScheme::crank_nicolson;
  const solvers::ThermalHistory full = solvers::thermal_history(b.mesh, spec, b.full);
  solvers::StepperRequest q;
  q.record_times = solvers::output_times(spec);
  const solvers::SteppedHistory red = solvers::step_thermal(b.model.system, spec, q);
  const double diff = max_difference(b.model.basis * red.states, full);
  std::printf("[reduction] staircase CN: max |reduced - full| %.2e K\n", diff);
  EXPECT_LT(diff, 0.01);
}

/// Only the sink moves (no speed, no heat): the sink input's response alone.
TEST(ReducedRun, FollowsATimeVaryingSink) {
  const Block& b = block();
  const core::CaseSpec spec = spec_of(block_case("[ { start_s = 0.0, speed_rpm = 0.0 } ]", 3600.0,
                                                 "[[0.0, 20.0], [600.0, 30.0], [2400.0, 15.0]]"));
  const solvers::ThermalHistory full = solvers::thermal_history(b.mesh, spec, b.full);
  const ReducedRun red = reduced_run(b.full, b.model, spec);
  const double diff = max_difference(red.temperature, full);
  std::printf("[reduction] sink: rise %.3f K, max |reduced - full| %.2e K\n", max_rise(full), diff);
  EXPECT_GT(max_rise(full), 1.0);
  EXPECT_LT(diff, 0.01);
}

/// A film state between and beyond the sampled ones (1500 and 9000 rpm): affine in h, still exact
/// enough, and the indicator says so.
TEST(ReducedRun, FollowsASpeedDependentFilmBeyondTheSampledSpeeds) {
  const Block& b = block();
  const core::CaseSpec spec = spec_of(block_case(
      "[ { start_s = 0.0, speed_rpm = 9000.0 }, { start_s = 1200.0, speed_rpm = 1500.0 } ]", 3600.0,
      kSteadySink));
  const solvers::ThermalHistory full = solvers::thermal_history(b.mesh, spec, b.full);
  const ReducedRun red = reduced_run(b.full, b.model, spec);
  const double diff = max_difference(red.temperature, full);
  const auto ind = solvers::error_indicator(b.full, b.model, red.samples);
  std::printf("[reduction] film: rise %.3f K, max |reduced - full| %.2e K, indicator %.2e K\n",
              max_rise(full), diff, ind.max_k);
  EXPECT_GT(max_rise(full), 5.0);
  EXPECT_LT(diff, 0.01);
}

TEST(ErrorIndicator, IsSmallOnAGoodBasisAndLargeOnATruncatedOne) {
  const Block& b = block();
  const core::CaseSpec spec = spec_of(block_case(kStaircase, 5400.0, kSwingingSink));
  const solvers::ThermalHistory full = solvers::thermal_history(b.mesh, spec, b.full);
  // The truncated basis: the load shapes and the steady responses only (no transient shifts).
  solvers::ReductionOptions poor;
  poor.speeds_rpm = {3000.0};
  poor.shifts_per_s = {0.0};
  poor.second_moment = false;
  const solvers::ReducedModel truncated = solvers::reduced_model(b.full, b.spec, poor);
  const ReducedRun good = reduced_run(b.full, b.model, spec);
  const ReducedRun bad = reduced_run(b.full, truncated, spec);
  const double good_error = max_difference(good.temperature, full);
  const double bad_error = max_difference(bad.temperature, full);
  const auto good_ind = solvers::error_indicator(b.full, b.model, good.samples);
  const auto bad_ind = solvers::error_indicator(b.full, truncated, bad.samples);
  std::printf(
      "[reduction] indicator: good r = %d error %.2e K indicator %.2e K; truncated r = %d "
      "error %.2e K indicator %.2e K\n",
      b.model.states(), good_error, good_ind.max_k, truncated.states(), bad_error, bad_ind.max_k);
  EXPECT_GT(bad_error, 0.01);
  EXPECT_TRUE(bad_ind.above_tolerance());
  EXPECT_FALSE(good_ind.above_tolerance());
  EXPECT_GT(bad_ind.max_k, 30 * good_ind.max_k);
  // Not too optimistic where it matters: within a factor 3 of the truncated run's real error.
  EXPECT_GT(bad_ind.max_k, bad_error / 3);
}

TEST(ReducedRun, FollowsHeatMovingWithTheFeedAxis) {
  const core::CaseSpec spec = spec_of(test_toml::gantry_bar(1));
  const mesh::TetMesh m = mesh::mesh_case(spec);
  const solvers::FullThermalSystem full = solvers::thermal_system(m, spec);
  const solvers::ReducedModel model = solvers::reduced_model(full, spec);
  // Another motion than the case's: a shorter stroke at another feed, then standing elsewhere.
  core::CaseSpec other = spec;
  other.feed_axis.segments = {
      {0.0, 0.1, 0.6, 0.15}, {240.0, 0.9, 0.9, 0.0}, {420.0, 0.3, 0.95, 0.05}};
  const solvers::ThermalHistory ref = solvers::thermal_history(m, other, full);
  const ReducedRun red = reduced_run(full, model, other);
  const double diff = max_difference(red.temperature, ref);
  const auto ind = solvers::error_indicator(full, model, red.samples);
  std::printf(
      "[reduction] moving: %d nodes, %d states, rise %.3f K, max |reduced - full| %.2e K, "
      "indicator %.2e K\n",
      static_cast<int>(full.states()), model.states(), max_rise(ref), diff, ind.max_k);
  EXPECT_GT(max_rise(ref), 0.5);
  EXPECT_LT(diff, 0.01);
  // The slices act alike: compressing each block to its principal directions keeps fewer states.
  solvers::ReductionOptions o;
  o.compression_tolerance = 1e-4;
  const solvers::ReducedModel small = solvers::reduced_model(full, spec, o);
  const double small_diff = max_difference(reduced_run(full, small, other).temperature, ref);
  std::printf("[reduction] moving, compressed 1e-4: %d states, max |reduced - full| %.2e K\n",
              small.states(), small_diff);
  EXPECT_LT(small.states(), model.states());
  EXPECT_LT(small_diff, 0.01);
}

TEST(ReducedModel, ProjectsOutputRowsAndRefusesAnotherCase) {
  const Block& b = block();
  // A row that reads one node: its projection is that node's row of V.
  Eigen::SparseMatrix<double> row(1, b.full.states());
  row.insert(0, 7) = 1.0;
  const Eigen::MatrixXd pr = solvers::project_rows(b.model, row);
  EXPECT_LT((pr.row(0) - b.model.basis.row(7)).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_THROW(solvers::project_rows(b.model, Eigen::MatrixXd::Ones(2, 5)), core::SolverError);
  // Another case: one convection entry more.
  core::CaseSpec other = b.spec;
  other.thermal.convection.push_back(other.thermal.convection.back());
  try {
    solvers::check_reducible(b.model, b.full, other);
    ADD_FAILURE() << "a case with another convection entry was accepted";
  } catch (const core::SolverError& e) {
    EXPECT_NE(std::string(e.what()).find("thermal.convection"), std::string::npos) << e.what();
  }
  solvers::ReductionOptions bad;
  bad.shifts_per_s = {-1.0};
  EXPECT_THROW(solvers::reduction_basis(b.full, b.spec, bad), core::SolverError);
}

}  // namespace
}  // namespace tt::reduction_test
