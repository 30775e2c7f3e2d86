// Temporal order of the two schemes, measured: a cube heated by a sink temperature that ramps
// linearly from the initial 20 degC to 120 degC over the run (smooth forcing, compatible initial
// state), steps halved three times on one mesh, errors against Crank-Nicolson at a step 16 times
// smaller than the finest (its own error is below 1e-3 of the finest errors measured).
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/thermal/thermal_fixtures.hpp"

namespace tt::thermal_test {
namespace {

/// Largest nodal difference over all output times [K].
double max_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

TEST(ThermalTimeOrder, BackwardEulerFirstCrankNicolsonSecond) {
  BoxCase cube;
  cube.max = {0.05, 0.05, 0.05};
  cube.max_edge = 0.0125;
  cube.density = 7800;
  cube.specific_heat = 460;
  cube.conductivity = 40;
  cube.extra = "[[boundary]]\nname = \"all\"\nrest = true\nselect = [ { bodies = [\"bar\"] } ]\n";
  cube.extra +=
      "[thermal]\ninitial_temperature_degC = 20.0\nstep_s = 40.0\noutput_interval_s = 120.0\n";
  cube.extra +=
      "[[thermal.convection]]\ngroup = \"all\"\nh_W_m2K = 200.0\n"
      "sink_table = [[0.0, 20.0], [600.0, 120.0]]\n";
  cube.extra += "[duty_cycle]\nend_s = 600.0\nsegments = [ { start_s = 0.0, speed_rpm = 0.0 } ]\n";
  core::CaseSpec spec = case_of(cube.toml());
  const mesh::TetMesh mesh = mesh::mesh_case(spec);
  const auto ops = solvers::thermal_system(mesh, spec);
  auto history = [&](core::TimeScheme scheme, double step) {
    spec.thermal.scheme = scheme;
    spec.thermal.step = step;
    return solvers::thermal_history(mesh, spec, ops).temperature;
  };
  const std::vector<double> steps = {40, 20, 10, 5};
  const Eigen::MatrixXd reference = history(core::TimeScheme::crank_nicolson, steps.back() / 16);
  const double rise = reference.maxCoeff() - reference.minCoeff();
  ASSERT_GT(rise, 50.0);  // the ramp really drives the cube
  for (auto scheme : {core::TimeScheme::backward_euler, core::TimeScheme::crank_nicolson}) {
    const bool be = scheme == core::TimeScheme::backward_euler;
    std::vector<double> errors;
    for (double step : steps) errors.push_back(max_difference(history(scheme, step), reference));
    for (size_t i = 1; i < steps.size(); ++i) {
      const double p = observed_order(steps[i - 1], errors[i - 1], steps[i], errors[i]);
      std::printf("[time order] %s dt %g -> %g s: error %.3e -> %.3e K, order %.3f\n",
                  be ? "BE" : "CN", steps[i - 1], steps[i], errors[i - 1], errors[i], p);
      if (be) {
        EXPECT_GT(p, 0.8);
        EXPECT_LT(p, 1.2);
      } else {
        EXPECT_GT(p, 1.7);
        EXPECT_LT(p, 2.3);
      }
    }
  }
  std::printf("[time order] %d nodes, rise %.1f K\n", static_cast<int>(mesh.nodes.rows()), rise);
}

}  // namespace
}  // namespace tt::thermal_test
