// One stepper for the full and a reduced system (issue 15): the dense instantiation
// (Eigen::LLT) of solvers::step_thermal on a densified small system gives the sparse (CHOLMOD)
// one's states, readouts, caller-column responses and energy, under both schemes, with heat that
// moves with the feed axis and a feed_power source.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/loads.hpp"
#include "solvers/thermal_stepper.hpp"
#include "tests/common/case_toml.hpp"
#include "tests/common/gantry_bar.hpp"

namespace tt::solvers {
namespace {

ReducedThermalSystem densified(const FullThermalSystem& s) {
  ReducedThermalSystem d;
  d.capacity = Eigen::MatrixXd(s.capacity);
  d.conduction = Eigen::MatrixXd(s.conduction);
  for (const auto& f : s.film) d.film.emplace_back(f);
  for (const auto& p : s.moving) d.moving.emplace_back(p);
  d.film_area = s.film_area;
  d.source_shape = s.source_shape;
  d.flux_area = s.flux_area;
  d.moving_source = s.moving_source;
  d.moving_pieces = s.moving_pieces;
  d.uniform = s.uniform;
  return with_moving_prefix(std::move(d));
}

/// Largest |a - b| / |b| over the entries.
double max_relative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return ((a - b).array().abs() / b.array().abs()).maxCoeff();
}

TEST(Stepper, DenseEqualsSparseOnASmallSystem) {
  for (const char* scheme : {"backward_euler", "crank_nicolson"}) {
    core::CaseSpec spec = io::case_from_toml(test_toml::gantry_bar(1, scheme), "bar.toml");
    for (auto& b : spec.bodies) b.max_edge = 0.06;  // a small system: a dense factor is cheap
    spec.duty_cycle.end = 400;                      // past the feed axis' stop at 300 s
    const mesh::TetMesh m = mesh::mesh_case(spec);
    const FullThermalSystem sparse = thermal_system(m, spec);
    ASSERT_LT(sparse.states(), 600);
    ASSERT_EQ(sparse.moving.size(), 1u);
    const ReducedThermalSystem dense = densified(sparse);

    StepperRequest q;
    q.record_times = output_times(spec);
    q.record_times.insert(q.record_times.begin(), 35.0);  // between step ends: interpolated
    const Eigen::Index n = sparse.states();
    q.base_readout.dense = Eigen::MatrixXd::Zero(2, n);
    q.base_readout.dense(0, 0) = 1;
    q.base_readout.dense(1, n - 1) = 1;
    q.base_readout.change = Eigen::MatrixXd::Ones(1, n) / static_cast<double>(n);
    q.column_readout = q.base_readout;
    q.shape_columns.push_back({sparse.film_area[0], [](double t, double) { return t / 100; }});
    q.load_columns.push_back([&](const StepView& s) {
      return Eigen::VectorXd(-(sparse.film[0] * (s.theta * *s.state1 + (1 - s.theta) * *s.state0)));
    });
    const SteppedHistory a = step_thermal(sparse, spec, q);
    const SteppedHistory b = step_thermal(dense, spec, q);
    ASSERT_EQ(a.states.cols(), b.states.cols());
    const double gap = max_relative(b.states, a.states);
    std::printf("[stepper] %s, %ld states: dense vs sparse, max relative difference %.2e\n", scheme,
                static_cast<long>(sparse.states()), gap);
    EXPECT_LE(gap, 1e-12) << scheme;
    EXPECT_LE(max_relative(b.readout.topRows(2), a.readout.topRows(2)), 1e-12) << scheme;
    EXPECT_LE((b.readout - a.readout).cwiseAbs().maxCoeff(),
              1e-12 * a.readout.cwiseAbs().maxCoeff())
        << scheme;
    ASSERT_EQ(a.responses.size(), 2u);
    for (size_t j = 0; j < 2; ++j)
      EXPECT_LE((b.responses[j] - a.responses[j]).cwiseAbs().maxCoeff(),
                1e-12 * a.responses[j].cwiseAbs().maxCoeff())
          << scheme << " column " << j;
    EXPECT_NEAR(b.heat_in, a.heat_in, 1e-12 * a.heat_in) << scheme;
    EXPECT_NEAR(b.lost, a.lost, 1e-12 * std::abs(a.heat_in)) << scheme;
    // The readout is the state's: rows of the recorded states, interpolated at 35 s too.
    EXPECT_NEAR(a.readout(0, 1), a.states(0, 1), 1e-12 * a.states(0, 1)) << scheme;
    EXPECT_GT(a.readout(2, a.readout.cols() - 1), 0.01) << scheme;  // the bar warms up
    EXPECT_GT(a.responses[0].cwiseAbs().maxCoeff(), 0.005) << scheme;
    EXPECT_GT(a.timings.factorizations, 0);
  }
}

// Factors kept between runs: a second run of the same system (assembled again) factors nothing
// and steps as a run of its own; a system with other matrices makes them forgotten, not misused.
TEST(Stepper, KeptFactorsServeTheNextRunAndAreForgottenForAnotherSystem) {
  core::CaseSpec spec = io::case_from_toml(test_toml::gantry_bar(1), "bar.toml");
  for (auto& b : spec.bodies) b.max_edge = 0.06;
  spec.duty_cycle.end = 400;
  const mesh::TetMesh m = mesh::mesh_case(spec);
  StepperRequest q;
  q.record_times = output_times(spec);
  KeptStepFactors<Eigen::SparseMatrix<double>> kept;
  const FullThermalSystem sys = thermal_system(m, spec);
  const SteppedHistory alone = step_thermal(sys, spec, q);
  const SteppedHistory first = step_thermal(sys, spec, q, {}, {}, &kept);
  EXPECT_EQ(first.states, alone.states);
  EXPECT_EQ(first.timings.factorizations, alone.timings.factorizations);
  ASSERT_GT(alone.timings.factorizations, 0);
  const FullThermalSystem again = thermal_system(m, spec);
  const SteppedHistory second = step_thermal(again, spec, q, {}, {}, &kept);
  EXPECT_EQ(second.states, alone.states);
  EXPECT_EQ(second.timings.factorizations, 0);
  core::CaseSpec other = spec;
  for (auto& mat : other.materials) mat.conductivity *= 2;
  const FullThermalSystem other_sys = thermal_system(m, other);
  const SteppedHistory other_alone = step_thermal(other_sys, other, q);
  const SteppedHistory other_kept = step_thermal(other_sys, other, q, {}, {}, &kept);
  EXPECT_EQ(other_kept.states, other_alone.states);
  EXPECT_EQ(other_kept.timings.factorizations, other_alone.timings.factorizations);
  EXPECT_GT((other_alone.states - alone.states).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(Stepper, RefusesRecordTimesOutOfOrderAndColumnsOfAnotherSize) {
  core::CaseSpec spec = io::case_from_toml(test_toml::gantry_bar(1), "bar.toml");
  for (auto& b : spec.bodies) b.max_edge = 0.06;
  const mesh::TetMesh m = mesh::mesh_case(spec);
  const FullThermalSystem sys = thermal_system(m, spec);
  StepperRequest q;
  q.record_times = {60.0, 30.0};
  EXPECT_THROW(step_thermal(sys, spec, q), core::SolverError);
  q.record_times = {60.0, spec.duty_cycle.end + 60};
  EXPECT_THROW(step_thermal(sys, spec, q), core::SolverError);
  q.record_times = {60.0};
  q.shape_columns.push_back({Eigen::VectorXd::Ones(3), [](double, double) { return 1.0; }});
  EXPECT_THROW(step_thermal(sys, spec, q), core::SolverError);
  q.shape_columns.clear();
  EXPECT_EQ(step_thermal(sys, spec, q).times, (std::vector<double>{0.0, 60.0}));
}

/// A steel block heated by a 20 W source whose heat grows by 2 %/K with its mean temperature
/// (about 25 K in 20 min: the heat grows by half).
core::CaseSpec warming_block(const std::string& scheme) {
  std::string t = test_toml::header("warming block") + test_toml::steel();
  t += test_toml::box_body("block", "steel", "0.025", "[0.0, 0.0, 0.0]", "[0.1, 0.05, 0.05]");
  t += "[mesh]\norder = 1\n[mechanical]\nenabled = false\n";
  t += "[[boundary]]\nname = \"all\"\nrest = true\nselect = [ {} ]\n";
  t += "[thermal]\nscheme = \"" + scheme + "\"\nstep_s = 20.0\noutput_interval_s = 60.0\n";
  t += "[[thermal.convection]]\ngroup = \"all\"\nh_W_m2K = 10.0\nsink_degC = 20.0\n";
  t += "[[thermal.heat_sources]]\nname = \"bearing\"\nbody = \"block\"\nlaw = \"constant\"\n"
       "power_ref_W = 20.0\ntemperature_coefficient_per_K = 0.02\n";
  t += "[duty_cycle]\nend_s = 1200.0\nsegments = [ { start_s = 0.0, speed_rpm = 0.0 } ]\n";
  return io::case_from_toml(t, "block.toml");
}

// Heat that grows with temperature, iterated to consistency within each step (SourceIteration):
// it settles in a few solves, and differs from the step-lagged law by a first-order amount (half
// at half the step), small against the source's rise and of the sign of the lag (the lagged
// power is the cooler step's, so the lagged block stays cooler).
TEST(Stepper, HeatGrowingWithTemperatureIteratedWithinTheStep) {
  for (const char* scheme : {"backward_euler", "crank_nicolson"}) {
    core::CaseSpec spec = warming_block(scheme);
    const mesh::TetMesh m = mesh::mesh_case(spec);
    const FullThermalSystem sys = thermal_system(m, spec);
    const double t0_k = spec.thermal.initial_temperature_c + core::kCelsiusOffset;
    int most_solves = 0;
    const auto rise = [&](double step, double tolerance) {
      spec.thermal.step = step;
      StepperRequest q;
      q.record_times = {spec.duty_cycle.end};
      q.sources.tolerance_K = tolerance;
      const SteppedHistory h = step_thermal(sys, spec, q);
      if (tolerance > 0) most_solves = std::max(most_solves, h.source_iterations);
      return sys.source_shape[0].dot(h.final_state) - t0_k;
    };
    const double lagged20 = rise(20, 0), iterated20 = rise(20, 1e-9);
    const double lagged10 = rise(10, 0), iterated10 = rise(10, 1e-9);
    const double d20 = iterated20 - lagged20, d10 = iterated10 - lagged10;
    std::printf(
        "[stepper] %s: source's rise %.4f K iterated, %.4f K lagged at 20 s (difference %.2e K), "
        "%.2e K at 10 s; at most %d solves a step\n",
        scheme, iterated20, lagged20, d20, d10, most_solves);
    EXPECT_GT(iterated20, 15) << scheme;
    EXPECT_GT(d20, 0) << scheme;
    EXPECT_LT(d20, 0.03 * iterated20) << scheme;
    EXPECT_NEAR(d10 / d20, 0.5, 0.1) << scheme;
    EXPECT_GE(most_solves, 2) << scheme;
    EXPECT_LE(most_solves, 8) << scheme;
  }
  // A step that has not settled within the solves allowed is an error, not a silent result.
  core::CaseSpec spec = warming_block("backward_euler");
  const mesh::TetMesh m = mesh::mesh_case(spec);
  const FullThermalSystem sys = thermal_system(m, spec);
  StepperRequest q;
  q.sources = {1e-300, 2};
  EXPECT_THROW(step_thermal(sys, spec, q), core::SolverError);
  q.sources = {-1, 30};
  EXPECT_THROW(step_thermal(sys, spec, q), core::SolverError);
}

}  // namespace
}  // namespace tt::solvers
