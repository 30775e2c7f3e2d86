// One stepper for the full and a reduced system (issue 15): the dense instantiation
// (Eigen::LLT) of solvers::step_thermal on a densified small system gives the sparse (CHOLMOD)
// one's states, readouts, caller-column responses and energy, under both schemes, with heat that
// moves with the feed axis and a feed_power source.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/loads.hpp"
#include "solvers/thermal_stepper.hpp"
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

}  // namespace
}  // namespace tt::solvers
