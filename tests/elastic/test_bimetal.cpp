// Timoshenko's bimetal strip (J. Opt. Soc. Am. 11 (1925) 233): two bonded layers of thickness
// t1 (bottom, E1, alpha1) and t2 (top, E2, alpha2) heated uniformly by dT bend to the curvature
//   1/rho = 6 (alpha2 - alpha1) dT (1 + m)^2 / (h (3 (1 + m)^2 + (1 + m n) (m^2 + 1 / (m n)))),
//   m = t1 / t2, n = E1 / E2, h = t1 + t2.
// Why a 3D strip of any width should reproduce it here: away from the ends (Saint-Venant) the
// axial strain is e + k y and sigma_xx = E (e + k y - alpha dT) + nu (sigma_yy + sigma_zz). The
// in-plane stresses of a traction-free cross-section have zero resultant and zero first moments
// (sigma_ab = div(sigma x_b) with no boundary traction), so with one Poisson ratio in both layers
// the axial force and bending moment balance is exactly the beam's, whatever the width. (Equal nu
// also makes the wide-plate limit, E -> E / (1 - nu), give the same curvature: only n enters.)
// So both layers share nu, the strip is held by 3-2-1 point supports (free: no reaction), and the
// curvature is read from u_y in the middle half, far from the end boundary layers (~ the section
// size). A clamped variant (the x = 0 face held in x, y, z) shows the same interior curvature;
// its tip deflection exceeds L^2 / (2 rho) by the clamp's boundary layer (the root section cannot
// expand or warp): measured +1.2 % at L/h = 20 and +0.63 % at L/h = 40, i.e. ~ 0.25 h / L.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "elastic_fixtures.hpp"

namespace tt::elastic_test {
namespace {

constexpr double kL = 0.1, kT1 = 0.003, kT2 = 0.002, kB = 0.005;  // [m]
constexpr double kE1 = 2.1e11, kE2 = 7.0e10, kNu = 0.3;           // [Pa], [-]
constexpr double kAlpha1 = 1.2e-5, kAlpha2 = 2.3e-5;              // [1/K]
constexpr double kDt = 50.0;                                      // [K]

/// Timoshenko's curvature [1/m], positive when the top layer (alpha2) ends up convex.
double timoshenko_curvature() {
  const double m = kT1 / kT2, n = kE1 / kE2, h = kT1 + kT2;
  return 6.0 * (kAlpha2 - kAlpha1) * kDt * (1 + m) * (1 + m) /
         (h * (3 * (1 + m) * (1 + m) + (1 + m * n) * (m * m + 1.0 / (m * n))));
}

/// The same from the beam's two balance equations, sum_i E_i int (e + k y - alpha_i dT) y^p dy = 0
/// for p = 0, 1 (layer 1 on y in [0, t1], layer 2 on [t1, t1 + t2]): k [1/m].
double beam_balance_curvature() {
  const double y[3] = {0.0, kT1, kT1 + kT2}, e[2] = {kE1, kE2}, a[2] = {kAlpha1, kAlpha2};
  Eigen::Matrix2d lhs = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  for (int i = 0; i < 2; ++i) {
    const double m0 = y[i + 1] - y[i];
    const double m1 = 0.5 * (y[i + 1] * y[i + 1] - y[i] * y[i]);
    const double m2 = (std::pow(y[i + 1], 3) - std::pow(y[i], 3)) / 3.0;
    lhs(0, 0) += e[i] * m0, lhs(0, 1) += e[i] * m1, rhs(0) += e[i] * a[i] * kDt * m0;
    lhs(1, 0) += e[i] * m1, lhs(1, 1) += e[i] * m2, rhs(1) += e[i] * a[i] * kDt * m1;
  }
  return lhs.partialPivLu().solve(rhs)(1);
}

BoxCase strip_case(double max_edge, bool clamped) {
  BoxCase c;
  c.materials = {{"invar_like", kE1, kNu, kAlpha1}, {"alu_like", kE2, kNu, kAlpha2}};
  c.bodies = {
      {"bottom", "invar_like", Eigen::Vector3d::Zero(), Eigen::Vector3d(kL, kT1, kB), max_edge},
      {"top", "alu_like", Eigen::Vector3d(0, kT1, 0), Eigen::Vector3d(kL, kT1 + kT2, kB),
       max_edge}};
  c.points = {{"A", Eigen::Vector3d::Zero()},
              {"B", Eigen::Vector3d(kL, 0, 0)},
              {"C", Eigen::Vector3d(0, 0, kB)}};
  c.boundary =
      "[[boundary]]\nname = \"root\"\nselect = [ { plane = { normal = [1.0, 0.0, 0.0], "
      "offset = 0.0 } } ]\n";
  c.mechanical = clamped ? "fixed = [\"root\"]"
                         : "point_supports = [ { point = \"A\" }, { point = \"B\", fixed = "
                           "[\"y\", \"z\"] }, { point = \"C\", fixed = [\"y\"] } ]";
  c.order = 2;
  return c;
}

struct StripResult {
  double fitted_curvature;   /// -2 x the x^2 coefficient of u_y fitted on x in [L/4, 3L/4] [1/m]
  double second_difference;  /// -(u(3L/4) + u(L/4) - 2 u(L/2)) / (L/4)^2 [1/m]
  double tip_deflection;     /// u_y(L, h/2, b/2) - u_y(0, h/2, b/2) [m]
};

StripResult strip_response(const mesh::TetMesh& mesh, const core::CaseSpec& spec) {
  const double tref = spec.mechanical.reference_temperature_c;
  const Eigen::VectorXd temp =
      nodal_temperature_k(mesh, [&](const Eigen::Vector3d&) { return tref + kDt; });
  const Eigen::VectorXd u = solvers::elastic_history(mesh, spec, temp).displacement.col(0);
  const double yc = 0.5 * (kT1 + kT2), zc = 0.5 * kB;
  auto uy = [&](double x) {
    return solvers::displacement_at(mesh, u, Eigen::Vector3d(x, yc, zc)).y();
  };
  const int samples = 21;
  Eigen::MatrixXd a(samples, 3);
  Eigen::VectorXd b(samples);
  for (int i = 0; i < samples; ++i) {
    const double s = (0.25 + 0.5 * i / (samples - 1.0)) * kL;
    const double xs = s / kL - 0.5;  // centred and scaled for conditioning
    a.row(i) << 1.0, xs, xs * xs;
    b(i) = uy(s);
  }
  const Eigen::Vector3d coef = a.colPivHouseholderQr().solve(b);
  const double q = 0.25 * kL;
  return {-2.0 * coef(2) / (kL * kL),
          -(uy(0.5 * kL + q) + uy(0.5 * kL - q) - 2 * uy(0.5 * kL)) / (q * q), uy(kL) - uy(0.0)};
}

TEST(Bimetal, FormulaMatchesBeamBalance) {
  // Guards the transcription of Timoshenko's formula against the beam equations it solves.
  EXPECT_NEAR(timoshenko_curvature() / beam_balance_curvature(), 1.0, 1e-12);
}

TEST(Bimetal, FreeAndClampedStripCurvatureWithin2Percent) {
  const double k = timoshenko_curvature();
  const auto free_spec = spec_of(strip_case(0.0025, false));
  const auto clamped_spec = spec_of(strip_case(0.0025, true));
  const auto mesh = mesh::mesh_case(free_spec);  // same geometry, groups and points for both
  const StripResult free = strip_response(mesh, free_spec);
  const StripResult clamped = strip_response(mesh, clamped_spec);
  const double tip = -0.5 * k * kL * kL;
  std::printf("[bimetal] %ld nodes (tet10), Timoshenko 1/rho = %.6e 1/m\n",
              static_cast<long>(mesh.nodes.rows()), k);
  std::printf(
      "[bimetal] free strip: fitted curvature %.6e (rel %+.2e), second difference %.6e "
      "(rel %+.2e)\n",
      free.fitted_curvature, free.fitted_curvature / k - 1, free.second_difference,
      free.second_difference / k - 1);
  std::printf(
      "[bimetal] clamped strip: fitted curvature %.6e (rel %+.2e), tip deflection %.6e m "
      "vs -L^2/(2 rho) = %.6e m (rel %+.2e)\n",
      clamped.fitted_curvature, clamped.fitted_curvature / k - 1, clamped.tip_deflection, tip,
      clamped.tip_deflection / tip - 1);
  EXPECT_NEAR(free.fitted_curvature / k, 1.0, 0.02);
  EXPECT_NEAR(free.second_difference / k, 1.0, 0.02);
  EXPECT_NEAR(clamped.fitted_curvature / k, 1.0, 0.02);
  EXPECT_NEAR(clamped.tip_deflection / tip, 1.0, 0.02);
}

}  // namespace
}  // namespace tt::elastic_test
