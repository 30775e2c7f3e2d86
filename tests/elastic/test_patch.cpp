// Patch test: a constant-strain state with non-zero stress reproduced on an unstructured mesh.
// The solver only holds dofs at zero and loads only by temperature, so the state is made by
// roller supports: a block of two bonded bodies stacked in y (E1 != E2, same nu and alpha) with
// every node on x = 0 and x = lx held in x, on y = 0 in y and on z = 0 in z, heated uniformly by
// dT. Then, exactly,
//   u = (0, (1 + nu) alpha dT y, (1 + nu) alpha dT z),  sigma_xx = -E_i alpha dT, others 0,
// which is linear (so exact for tet4 and tet10), continuous across the interface (the tangential
// strains eps_xx = 0 and eps_zz = (1 + nu) alpha dT agree on both sides because nu and alpha do)
// and in equilibrium (sigma_yy = 0 is the traction across the interface). The rollers are point
// supports: a named point is added to the mesh for each boundary node, as the API allows.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "elastic_fixtures.hpp"

namespace tt::elastic_test {
namespace {

constexpr double kE1 = 2.1e11, kE2 = 0.9e11, kNu = 0.28, kAlpha = 1.1e-5, kDt = 25.0;
const Eigen::Vector3d kSize(0.08, 0.04, 0.03);  // [m]; the bodies meet at y = kSize.y() / 2

struct Rollers {
  mesh::TetMesh mesh;
  core::CaseSpec spec;
};

/// The mesh with one named point per node on a roller plane, and the spec's point supports on
/// them (an anchor support at the origin lets the case file itself pass the reader's check).
/// Rollers on x = 0 and x = lx (in x) and z = 0 (in z); on y = 0 (in y) when `y_rollers`, else
/// only the origin is held in y.
Rollers roller_block(int order, bool y_rollers = true) {
  BoxCase c;
  c.materials = {{"stiff", kE1, kNu, kAlpha}, {"soft", kE2, kNu, kAlpha}};
  const double yi = 0.5 * kSize.y();
  c.bodies = {{"bottom", "stiff", Eigen::Vector3d::Zero(),
               Eigen::Vector3d(kSize.x(), yi, kSize.z()), 0.012},
              {"top", "soft", Eigen::Vector3d(0, yi, 0), kSize, 0.012}};
  c.points = {{"O", Eigen::Vector3d::Zero()}};
  c.mechanical = "point_supports = [ { point = \"O\" } ]";
  c.order = order;
  Rollers r{mesh::TetMesh{}, spec_of(c)};
  r.mesh = mesh::mesh_case(r.spec);
  r.spec.mechanical.point_supports.clear();
  if (!y_rollers) r.spec.mechanical.point_supports.push_back({"O", {false, true, false}});
  const double tol = 1e-9;
  for (Eigen::Index i = 0; i < r.mesh.nodes.rows(); ++i) {
    const Eigen::Vector3d x = r.mesh.nodes.row(i).transpose();
    const std::array<bool, 3> held = {std::abs(x.x()) < tol || std::abs(x.x() - kSize.x()) < tol,
                                      y_rollers && std::abs(x.y()) < tol, std::abs(x.z()) < tol};
    if (!held[0] && !held[1] && !held[2]) continue;
    const std::string id = "roller" + std::to_string(i);
    r.mesh.points.push_back(mesh::NamedNode{id, x, static_cast<int>(i)});
    r.spec.mechanical.point_supports.push_back(core::PointSupport{id, held});
  }
  return r;
}

class Patch : public ::testing::TestWithParam<int> {};

TEST_P(Patch, RollerBlockReproducesConstantStrainExactly) {
  const int order = GetParam();
  const Rollers r = roller_block(order);
  const double tref = r.spec.mechanical.reference_temperature_c;
  const Eigen::VectorXd temp =
      nodal_temperature_k(r.mesh, [&](const Eigen::Vector3d&) { return tref + kDt; });
  const Eigen::VectorXd u = solvers::elastic_history(r.mesh, r.spec, temp).displacement.col(0);

  const double e_t = (1 + kNu) * kAlpha * kDt;
  Eigen::VectorXd exact(u.size());
  for (Eigen::Index i = 0; i < r.mesh.nodes.rows(); ++i)
    exact.segment<3>(3 * i) =
        Eigen::Vector3d(0, e_t * r.mesh.nodes(i, 1), e_t * r.mesh.nodes(i, 2));
  const double err = max_relative_error(u, exact);

  // Von Mises is |sigma_xx| = E_i alpha dT at nodes inside body i (interface nodes average both).
  const Eigen::VectorXd vm = solvers::von_mises_nodal(r.mesh, r.spec, u, temp);
  const double yi = 0.5 * kSize.y();
  double stress_err = 0;
  int inside = 0;
  for (Eigen::Index i = 0; i < r.mesh.nodes.rows(); ++i) {
    const double y = r.mesh.nodes(i, 1);
    if (std::abs(y - yi) < 1e-9) continue;
    const double expected = (y < yi ? kE1 : kE2) * kAlpha * kDt;
    stress_err = std::max(stress_err, std::abs(vm(i) / expected - 1));
    ++inside;
  }
  std::printf(
      "[patch] order %d: %ld nodes, %zu roller nodes, displacement error %.2e, max "
      "|von Mises / (E_i alpha dT) - 1| = %.2e over %d nodes\n",
      order, static_cast<long>(r.mesh.nodes.rows()), r.spec.mechanical.point_supports.size(), err,
      stress_err, inside);
  EXPECT_LT(err, 1e-10);
  EXPECT_LT(stress_err, 1e-9);
  EXPECT_GT(inside, 0);
}

// A linear stress field: the same rollers but y held only at the origin, and dT = a + b y. Then
//   u = (0, (1 + nu) alpha (a y + b y^2 / 2 - b z^2 / 2), (1 + nu) alpha (a + b y) z),
//   sigma_xx = -E_i alpha (a + b y), others 0
// (eps_yz = 0 because the z^2 term cancels d u_z / dy; the y faces are free). The displacement
// is quadratic, so tet10 is exact, and the nodal von Mises E_i alpha |a + b y| varies along y:
// a stress evaluated at the wrong natural point of a node (e.g. a mid-edge node mixed up) or with
// the wrong element temperature shows here, where the constant-stress tests above cannot see it.
TEST(LinearStressPatch, RollerBlockWithLinearTemperatureIsExactOnTet10) {
  const Rollers r = roller_block(2, false);
  const double tref = r.spec.mechanical.reference_temperature_c, a = 10.0, b = 750.0;  // K, K/m
  const Eigen::VectorXd temp =
      nodal_temperature_k(r.mesh, [&](const Eigen::Vector3d& x) { return tref + a + b * x.y(); });
  const Eigen::VectorXd u = solvers::elastic_history(r.mesh, r.spec, temp).displacement.col(0);

  const double g = (1 + kNu) * kAlpha;
  Eigen::VectorXd exact(u.size());
  for (Eigen::Index i = 0; i < r.mesh.nodes.rows(); ++i) {
    const double y = r.mesh.nodes(i, 1), z = r.mesh.nodes(i, 2);
    exact.segment<3>(3 * i) =
        Eigen::Vector3d(0, g * (a * y + 0.5 * b * (y * y - z * z)), g * (a + b * y) * z);
  }
  const double err = max_relative_error(u, exact);
  const Eigen::VectorXd vm = solvers::von_mises_nodal(r.mesh, r.spec, u, temp);
  const double yi = 0.5 * kSize.y();
  double stress_err = 0;
  for (Eigen::Index i = 0; i < r.mesh.nodes.rows(); ++i) {
    const double y = r.mesh.nodes(i, 1);
    if (std::abs(y - yi) < 1e-9) continue;
    const double expected = (y < yi ? kE1 : kE2) * kAlpha * (a + b * y);
    stress_err =
        std::max(stress_err, std::abs(vm(i) - expected) / (kE1 * kAlpha * (a + b * kSize.y())));
  }
  std::printf(
      "[patch] linear stress, tet10: %ld nodes, displacement error %.2e, max |von Mises "
      "- E_i alpha dT(y)| / max = %.2e\n",
      static_cast<long>(r.mesh.nodes.rows()), err, stress_err);
  EXPECT_LT(err, 1e-10);
  EXPECT_LT(stress_err, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Orders, Patch, ::testing::Values(1, 2),
                         [](const auto& info) { return "order" + std::to_string(info.param); });

}  // namespace
}  // namespace tt::elastic_test
