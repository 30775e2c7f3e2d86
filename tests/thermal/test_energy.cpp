// Energy bookkeeping of the transient solver on a small two-body case with sources, convection
// (speed-dependent h, a time-varying sink) and a duty cycle with stops: heat in - stored - lost
// closes to round-off for both schemes and both element orders, and the heat in equals the
// sources' laws integrated over the duty cycle. Also the undershoot of consistent-mass 4-node
// tets under a sudden heat input, with bounds asserted only where they must hold.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/common/case_toml.hpp"
#include "tests/thermal/thermal_fixtures.hpp"

namespace tt::thermal_test {
namespace {

struct EnergyCase {
  int order = 1;
  std::string scheme = "backward_euler";
  bool lumped = false;
  std::string sources =
      "[[thermal.heat_sources]]\nname = \"base\"\nbody = \"block\"\nlaw = \"constant\"\n"
      "power_ref_W = 5.0\n"
      "[[thermal.heat_sources]]\nname = \"bearing\"\nbody = \"pad\"\nlaw = \"speed_power\"\n"
      "power_ref_W = 20.0\nref_speed_rpm = 3000.0\nexponent = 1.5\n";
  std::string convection =
      "[[thermal.convection]]\ngroup = \"top\"\nh_W_m2K = 10.0\nh_speed_gain_W_m2K = 15.0\n"
      "speed_ref_rpm = 3000.0\nsink_table = [[0.0, 20.0], [450.0, 25.0], [900.0, 22.0]]\n"
      "[[thermal.convection]]\ngroup = \"rest\"\nh_W_m2K = 5.0\nsink_degC = 20.0\n";
  std::string fluxes;
  double step = 7.0, end = 900.0;
  std::string segments =
      "[ { start_s = 0.0, speed_rpm = 3000.0 }, { start_s = 300.0, speed_rpm = 0.0 }, "
      "{ start_s = 500.0, speed_rpm = 1500.0 } ]";

  std::string toml() const {
    std::string t = test_toml::header("energy");
    t += "[materials.iron]\ndensity_kg_m3 = 7250.0\nspecific_heat_J_kgK = 510.0\n"
         "conductivity_W_mK = 46.0\nyoungs_modulus_Pa = 1.2e11\npoisson_ratio = 0.26\n"
         "expansion_per_K = 1.1e-5\n";
    t += test_toml::box_body("block", "iron", "0.02", "[0.0, 0.0, 0.0]", "[0.1, 0.05, 0.04]");
    t += test_toml::box_body("pad", "iron", "0.015", "[0.1, 0.0, 0.0]", "[0.13, 0.05, 0.04]");
    t += "[mesh]\norder = " + std::to_string(order) + "\n[mechanical]\nenabled = false\n";
    t += "[[boundary]]\nname = \"top\"\nselect = [ { bodies = [\"block\", \"pad\"], plane = { "
         "normal = [0.0, 1.0, 0.0], offset = 0.05 } } ]\n";
    t += "[[boundary]]\nname = \"lid\"\nselect = [ { bodies = [\"block\"], plane = { "
         "normal = [0.0, 0.0, 1.0], offset = 0.04 } } ]\n";
    t += "[[boundary]]\nname = \"rest\"\nrest = true\nselect = [ { bodies = [\"block\", \"pad\"] "
         "} ]\n";
    t += "[thermal]\ninitial_temperature_degC = 20.0\nscheme = \"" + scheme +
         "\"\nstep_s = " + num(step) + "\noutput_interval_s = " + num(end / 10) +
         "\nlumped_mass = " + (lumped ? "true" : "false") + "\n";
    t += convection + sources + fluxes;
    t += "[duty_cycle]\nend_s = " + num(end) + "\nsegments = " + segments + "\n";
    return t;
  }
};

// 5 W for 900 s, 20 W for 300 s at 3000 rpm, 20 (1/2)^1.5 W for 400 s at 1500 rpm [J].
const double kHeatByHand = 5 * 900 + 20 * 300 + 20 * std::pow(0.5, 1.5) * 400;

TEST(ThermalEnergy, ClosesForBothSchemesAndOrders) {
  for (int order : {1, 2}) {
    EnergyCase c;
    c.order = order;
    core::CaseSpec spec = case_of(c.toml());
    const mesh::TetMesh mesh = mesh::mesh_case(spec);
    const auto ops = solvers::thermal_system(mesh, spec);
    for (auto scheme : {core::TimeScheme::backward_euler, core::TimeScheme::crank_nicolson}) {
      spec.thermal.scheme = scheme;
      const auto h = solvers::thermal_history(mesh, spec, ops);
      const auto& e = h.energy;
      std::printf("[energy] tet%d %s: in %.6f J, stored %.6f J, lost %.6f J, closure %.2e\n",
                  mesh.nodes_per_tet(), scheme == core::TimeScheme::backward_euler ? "BE" : "CN",
                  e.heat_in, e.stored, e.lost, e.closure());
      EXPECT_LT(std::abs(e.closure()), 1e-9);
      EXPECT_NEAR(e.heat_in, kHeatByHand, 1e-9 * kHeatByHand);
      EXPECT_NEAR(e.heat_in_law, kHeatByHand, 1e-9 * kHeatByHand);
      // Both sinks of the balance are really exercised.
      EXPECT_GT(e.stored, 0.1 * e.heat_in);
      EXPECT_GT(e.lost, 0.01 * e.heat_in);
    }
  }
}

// Row-sum lumping of the tet4 gives every node int N rho c dV, so the quadrature of the stored
// heat is the scheme's own energy and the balance closes to round-off.
TEST(ThermalEnergy, ClosesWithLumpedCapacityOnLinearTets) {
  EnergyCase c;
  c.lumped = true;
  const Solution run = run_case(case_of(c.toml()));
  std::printf("[energy] tet4 BE lumped: closure %.2e\n", run.history.energy.closure());
  EXPECT_LT(std::abs(run.history.energy.closure()), 1e-9);
}

// HRZ lumping of the tet10 (corners rho c V / 36, mid-edge nodes 4 rho c V / 27) conserves
// sum_i m_i (T_i - T0), not the quadrature of rho c (T - T0) that EnergyBalance::stored reports
// (the integrals of the corner shape functions are negative, -V/20). The scheme's own balance
// must close to round-off; the reported closure is then only as small as the difference of the
// two energy measures, O(h^2) (measured 2.6e-4 here).
TEST(ThermalEnergy, LumpedQuadraticTetsConserveTheirOwnEnergy) {
  EnergyCase c;
  c.order = 2;
  c.lumped = true;
  const auto spec = case_of(c.toml());
  const mesh::TetMesh mesh = mesh::mesh_case(spec);
  const auto ops = solvers::thermal_system(mesh, spec);
  const auto h = solvers::thermal_history(mesh, spec, ops);
  const double t0 = spec.thermal.initial_temperature_c + core::kCelsiusOffset;
  const Eigen::VectorXd rise = h.temperature.col(h.temperature.cols() - 1) -
                               Eigen::VectorXd::Constant(mesh.nodes.rows(), t0);
  const double stored_discrete = (ops.capacity * rise).sum();
  const double discrete_closure =
      (h.energy.heat_in - stored_discrete - h.energy.lost) / h.energy.heat_in;
  std::printf("[energy] tet10 BE lumped: reported closure %.2e, with sum_i m_i dT_i %.2e\n",
              h.energy.closure(), discrete_closure);
  EXPECT_LT(std::abs(discrete_closure), 1e-9);
  EXPECT_LT(std::abs(h.energy.closure()), 1e-3);
}

const char* kSpeedFlux =
    "[[thermal.surface_flux]]\ngroup = \"lid\"\nflux_W_m2 = 1000.0\nfollows_speed = true\n"
    "ref_speed_rpm = 3000.0\n";
// The lid is 0.1 m x 0.05 m; the flux runs at full speed 300 s and at half speed 400 s [J].
const double kSpeedFluxHeat = 1000 * 0.1 * 0.05 * (300 + 0.5 * 400);

TEST(ThermalEnergy, SpeedFollowingFluxEntersTheBalance) {
  EnergyCase c;
  c.fluxes = kSpeedFlux;
  const Solution run = run_case(case_of(c.toml()));
  const auto& e = run.history.energy;
  std::printf("[energy] speed-following flux: in %.6f J, law %.6f J, by hand %.6f J\n", e.heat_in,
              e.heat_in_law, kHeatByHand + kSpeedFluxHeat);
  EXPECT_NEAR(e.heat_in, kHeatByHand + kSpeedFluxHeat, 1e-9 * e.heat_in);
  EXPECT_LT(std::abs(e.closure()), 1e-9);
}

TEST(ThermalEnergy, SpeedFollowingFluxCountsInTheLaw) {
  EnergyCase c;
  c.fluxes = kSpeedFlux;
  const Solution run = run_case(case_of(c.toml()));
  EXPECT_NEAR(run.history.energy.heat_in_law, kHeatByHand + kSpeedFluxHeat,
              1e-9 * run.history.energy.heat_in);
}

// A sudden 1e5 W/m^2 on the lid of an otherwise insulated block, steps of 0.05 s on 20 mm tets
// (the heat penetrates sqrt(alpha dt) = 0.6 mm per step). Consistent mass then drives the nodes
// one layer below the lid under T0 (measured -1.46 K against a 13.7 K peak rise); row-sum
// lumping cuts it to -0.26 K but cannot remove it, because TetGen's obtuse dihedral angles give
// K positive off-diagonal entries (no discrete maximum principle). So T >= T0 is NOT asserted;
// what must hold is: the capacity-weighted rise equals the heat in at every output, the lid
// (where the heat enters) is warmer on average than the body, and lumping reduces the
// undershoot. The 15 % bound on the consistent undershoot is a regression guard, not a theorem.
TEST(ThermalEnergy, SuddenHeatInputUndershootStaysBounded) {
  const double flux = 1e5, lid_area = 0.1 * 0.05;  // [W/m^2], [m^2]
  std::vector<double> undershoot;
  for (bool lumped : {false, true}) {
    EnergyCase c;
    c.lumped = lumped;
    c.sources.clear();
    c.convection.clear();
    c.fluxes = "[[thermal.surface_flux]]\ngroup = \"lid\"\nflux_W_m2 = " + num(flux) + "\n";
    c.segments = "[ { start_s = 0.0, speed_rpm = 0.0 } ]";
    c.step = 0.05;
    c.end = 2.0;
    const auto spec = case_of(c.toml());
    const mesh::TetMesh mesh = mesh::mesh_case(spec);
    const auto ops = solvers::thermal_system(mesh, spec);
    const auto h = solvers::thermal_history(mesh, spec, ops);
    const double t0 = spec.thermal.initial_temperature_c + core::kCelsiusOffset;
    const double volume = 0.13 * 0.05 * 0.04, rho_c = 7250.0 * 510.0;
    const Eigen::VectorXd lid_weight = ops.flux_area[0] / ops.flux_area[0].sum();
    ASSERT_NEAR(ops.flux_area[0].sum(), lid_area, 1e-12);
    double worst = 0, peak = 0;
    for (int col = 1; col < h.temperature.cols(); ++col) {
      const Eigen::VectorXd rise =
          h.temperature.col(col) - Eigen::VectorXd::Constant(mesh.nodes.rows(), t0);
      const double heat = flux * lid_area * h.times[col];
      EXPECT_NEAR((ops.capacity * rise).sum(), heat, 1e-9 * heat) << "t = " << h.times[col];
      const double body_mean = heat / (rho_c * volume);
      EXPECT_GT(lid_weight.dot(rise), body_mean) << "t = " << h.times[col];
      worst = std::min(worst, rise.minCoeff());
      peak = std::max(peak, rise.maxCoeff());
    }
    std::printf("[undershoot] %s mass: min T - T0 = %.3f K, max T - T0 = %.3f K\n",
                lumped ? "lumped" : "consistent", worst, peak);
    EXPECT_LT(-worst, 0.15 * peak);
    // Lumped backward Euler with a Z-matrix K (off-diagonals <= 0) has a nonnegative inverse
    // of M + dt K, so there the bound T >= T0 must hold.
    double max_off_diagonal = -1e300;
    for (int j = 0; j < ops.conduction.outerSize(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(ops.conduction, j); it; ++it)
        if (it.row() != j) max_off_diagonal = std::max(max_off_diagonal, it.value());
    std::printf("[undershoot] largest off-diagonal of K: %.3g W/K\n", max_off_diagonal);
    if (lumped && max_off_diagonal <= 0) {
      EXPECT_GE(worst, -1e-12 * peak);
    }
    undershoot.push_back(-worst);
  }
  EXPECT_LT(undershoot[1], undershoot[0]);  // lumping helps
}

}  // namespace
}  // namespace tt::thermal_test
