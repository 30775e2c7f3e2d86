// Calibration's declared model and `run` step one system with one stepper (issue 15): on the
// gantry bar (heat moving with the feed axis, and a feed_power source), the channels that
// calibration's march reads equal thermal_history's read at the same points, under both schemes;
// and the march's columns are the linear responses of the declared model.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "calibration/model.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/thermal.hpp"
#include "tests/common/gantry_bar.hpp"

namespace tt::calibration {
namespace {

/// A measured run of the bar: the spindle stands (the feed axis moves), four located sensors
/// (in the stroke, at its end, beyond it, in the feed_power source's pad), samples every 10 s.
io::MeasuredRun bar_run() {
  io::MeasuredRun run;
  run.run = "bar";
  run.inputs = {"speed_rpm"};
  const Eigen::Index n = 61;
  run.time = Eigen::VectorXd::LinSpaced(n, 0.0, 600.0);
  run.input_values = Eigen::MatrixXd::Zero(n, 1);
  for (const auto& [id, x] : std::vector<std::pair<std::string, double>>{
           {"mid", 0.5}, {"end", 0.8}, {"far", 0.97}, {"pad", -0.025}})
    run.sensors.push_back({id, Eigen::Vector3d(x, 0.025, 0.025)});
  run.temperature = Eigen::MatrixXd::Zero(n, 4);
  return run;
}

/// Largest |a - b| / |b| over the entries.
double max_relative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return ((a - b).array().abs() / b.array().abs()).maxCoeff();
}

TEST(March, DeclaredChannelsEqualRunWithMovingAndFeedPowerHeat) {
  for (const char* scheme : {"backward_euler", "crank_nicolson"}) {
    const core::CaseSpec declared =
        io::case_from_toml(test_toml::gantry_bar(1, scheme), "bar.toml");
    const mesh::TetMesh m = mesh::mesh_case(declared);
    const io::MeasuredRun run = bar_run();
    const Readout r = readout(m, declared, run);
    ASSERT_EQ(r.channels(), 4);
    const core::CaseSpec spec = case_for_run(declared, run);
    const Responses march_out = march(m, spec, r, run.time, {}, {});

    // `run`'s path: thermal_history at every step end, read at the sensors.
    const solvers::ThermalHistory th =
        solvers::thermal_history(m, spec, solvers::thermal_system(m, spec));
    ASSERT_EQ(th.times.size(), static_cast<size_t>(run.time.size()));
    const Eigen::MatrixXd from_run = (r.temperature * th.temperature).transpose();
    const double gap = max_relative(march_out.base, from_run);
    std::printf("[march] %s: march vs thermal_history, max relative difference %.2e\n", scheme,
                gap);
    EXPECT_LE(gap, 1e-10) << scheme;
    EXPECT_LE(max_relative(simulated_channels(m, spec, r, run.time), from_run), 1e-10) << scheme;

    // The loads are there: the feed_power pad and the stroke warm up, the far end least.
    const double t0 = declared.thermal.initial_temperature_c + solvers::kCelsiusOffset;
    const Eigen::RowVectorXd rise = march_out.base.row(run.time.size() - 1).array() - t0;
    EXPECT_GT(rise(3), 0.01) << scheme;  // the pad's feed_power source (2.88 W for 300 s)
    EXPECT_GT(rise(0), rise(2) + 0.05) << scheme;
  }
}

TEST(March, ColumnsAreLinearResponses) {
  for (const char* scheme : {"backward_euler", "crank_nicolson"}) {
    const core::CaseSpec declared =
        io::case_from_toml(test_toml::gantry_bar(1, scheme), "bar.toml");
    const mesh::TetMesh m = mesh::mesh_case(declared);
    const io::MeasuredRun run = bar_run();
    const Readout r = readout(m, declared, run);
    const core::CaseSpec spec = case_for_run(declared, run);
    const solvers::FullThermalSystem sys = solvers::thermal_system(m, spec);
    const double h = spec.thermal.convection[0].h;
    // One kelvin more air: as a fixed shape, and as a load of the step.
    SeparableColumn air{"air", h * sys.film_area[0], [](double, double) { return 1.0; }};
    LoadColumn air_load{
        "air", [&](const solvers::StepView&) { return Eigen::VectorXd(h * sys.film_area[0]); }};
    const Responses out = march(m, spec, r, run.time, {air}, {air_load});
    ASSERT_EQ(out.columns.size(), 2u);
    core::CaseSpec warmer = spec;
    warmer.thermal.convection[0].sink.value[0] += 1;
    const Responses again = march(m, warmer, r, run.time, {}, {});
    const Eigen::MatrixXd difference = again.base - out.base;
    EXPECT_LE((out.columns[0] - difference).cwiseAbs().maxCoeff(), 1e-9) << scheme;
    EXPECT_LE((out.columns[1] - out.columns[0]).cwiseAbs().maxCoeff(), 1e-12) << scheme;
    EXPECT_GT(out.columns[0].bottomRows(1).minCoeff(), 0.05) << scheme;
  }
}

}  // namespace
}  // namespace tt::calibration
