// NAFEMS T3, one-dimensional transient heat transfer: a 0.1 m bar (k = 35 W/(m K),
// rho = 7200 kg/m^3, c = 440.5 J/(kg K)) at 0 degC, held at 0 degC at x = 0 while the end x = 0.1
// follows 100 sin(pi t / 40) degC; target T(x = 0.08 m, t = 32 s) = 36.60 degC. A 1D
// finite-difference solution (800 cells, CN at 5 ms) gives 36.603 degC.
//
// The solver has no prescribed-temperature boundary: both ends are convective with
// h = 1e9 W/(m^2 K). The film then carries the end flux, at most k x 100 K / sqrt(alpha t)
// = 2e5 W/m^2, with a drop of 2e-4 K: negligible against the 0.37 K (1 %) tolerance. The sine
// is a sink table sampled every 0.25 s (linear-interpolation error 100 (pi/40)^2 0.25^2 / 8
// = 5e-3 K at most).
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/thermal/thermal_fixtures.hpp"

namespace tt::thermal_test {
namespace {

constexpr double kTarget = 36.60;  // [degC]

std::string t3_toml(double max_edge, int order) {
  BoxCase bar;
  bar.max = {0.1, 0.005, 0.005};
  bar.max_edge = max_edge;
  bar.order = order;
  bar.extra = plane_group("cold_end", {1, 0, 0}, 0.0) + plane_group("driven_end", {1, 0, 0}, 0.1);
  bar.extra += "[points]\nlist = [ { id = \"P\", position = " + vec3(0.08, 0.0025, 0.0) + " } ]\n";
  bar.extra +=
      "[thermal]\ninitial_temperature_degC = 0.0\nscheme = \"crank_nicolson\"\n"
      "step_s = 0.125\noutput_interval_s = 8.0\n";
  bar.extra += "[[thermal.convection]]\ngroup = \"cold_end\"\nh_W_m2K = 1e9\nsink_degC = 0.0\n";
  bar.extra += "[[thermal.convection]]\ngroup = \"driven_end\"\nh_W_m2K = 1e9\nsink_table = " +
               sink_table([](double t) { return 100 * std::sin(kPi * t / 40); }, 32.0, 128) + "\n";
  bar.extra += "[duty_cycle]\nend_s = 32.0\nsegments = [ { start_s = 0.0, speed_rpm = 0.0 } ]\n";
  return bar.toml();
}

TEST(ThermalNafemsT3, ConvergesToTargetUnderRefinement) {
  std::vector<double> errors;
  for (double max_edge : {0.02, 0.01, 0.005, 0.0025}) {
    const Solution run = run_case(case_of(t3_toml(max_edge, 1)));
    const double t = celsius_at(run, "P", 32.0);
    errors.push_back(std::abs(t - kTarget));
    std::printf("[T3] tet4 max_edge %.4f m: %d nodes, T = %.4f degC, error %.3f %%\n", max_edge,
                static_cast<int>(run.mesh.nodes.rows()), t, 100 * errors.back() / kTarget);
  }
  for (size_t i = 1; i < errors.size(); ++i)
    EXPECT_LT(errors[i], errors[i - 1]) << "refinement " << i << " did not reduce the error";
  EXPECT_LT(errors.back(), 0.01 * kTarget);
}

TEST(ThermalNafemsT3, QuadraticTetsHitTarget) {
  const Solution run = run_case(case_of(t3_toml(0.005, 2)));
  const double t = celsius_at(run, "P", 32.0);
  std::printf("[T3] tet10 max_edge 0.005 m: %d nodes, T = %.4f degC, error %.3f %%\n",
              static_cast<int>(run.mesh.nodes.rows()), t, 100 * std::abs(t - kTarget) / kTarget);
  EXPECT_NEAR(t, kTarget, 0.01 * kTarget);
}

}  // namespace
}  // namespace tt::thermal_test
