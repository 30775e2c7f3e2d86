// Thermo-elastic kernels: rigid modes, patch test, free thermal expansion, exact thermal load,
// agreement with B^T D B, and unit scaling.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "core/errors.hpp"
#include "solvers/kernels/elasticity.hpp"
#include "solvers/kernels/quadrature.hpp"
#include "tests/kernels/fixtures.hpp"

namespace tt::solvers::kernels {
namespace {

using testing::curved_tet10;
using testing::distorted_tet4;
using testing::straight_tet10;

const ElasticMaterial cast_iron{1.2e11, 0.26, 1.05e-5};

/// Node-major dofs of the displacement field u(p) at the element's nodes.
template <int N, class Field>
Eigen::Matrix<double, 3 * N, 1> nodal_displacements(const Eigen::Matrix<double, 3, N>& x,
                                                    Field field) {
  Eigen::Matrix<double, 3 * N, 1> u;
  for (int a = 0; a < N; ++a) u.template segment<3>(3 * a) = field(Eigen::Vector3d(x.col(a)));
  return u;
}

/// 3n x 6 rigid-body modes: 3 translations and 3 rotations about the element's centroid.
template <int N>
Eigen::Matrix<double, 3 * N, 6> rigid_modes(const Eigen::Matrix<double, 3, N>& x) {
  const Eigen::Vector3d c = x.rowwise().mean();
  Eigen::Matrix<double, 3 * N, 6> r;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d unit = Eigen::Vector3d::Unit(k);
    r.col(k) = nodal_displacements<N>(x, [&](const Eigen::Vector3d&) { return unit; });
    r.col(3 + k) = nodal_displacements<N>(
        x, [&](const Eigen::Vector3d& p) { return Eigen::Vector3d(unit.cross(p - c)); });
  }
  return r;
}

template <int N>
void expect_stiffness_properties(const Eigen::Matrix<double, 3, N>& x) {
  constexpr int D = 3 * N;
  const Eigen::Matrix<double, D, D> k = stiffness_matrix(x, cast_iron, 0);
  EXPECT_LT((k - k.transpose()).norm(), 1e-14 * k.norm());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>> eig(k);
  const Eigen::Matrix<double, D, 1> lambda = eig.eigenvalues();
  for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(lambda(i)), 1e-11 * lambda(D - 1)) << i;
  EXPECT_GT(lambda(6), 1e-6 * lambda(D - 1)) << "more than six zero-energy modes";
  const Eigen::Matrix<double, D, 6> r = rigid_modes<N>(x);
  for (int m = 0; m < 6; ++m) {
    EXPECT_LT((k * r.col(m)).norm(), 1e-11 * k.norm() * r.col(m).norm()) << "rigid mode " << m;
  }
}

TEST(Elasticity, StiffnessSymmetricPsdWithSixRigidModes) {
  expect_stiffness_properties<4>(distorted_tet4());
  expect_stiffness_properties<10>(straight_tet10(distorted_tet4()));
  expect_stiffness_properties<10>(curved_tet10());
}

TEST(Elasticity, ElasticityMatrixInvertsToHookesLaw) {
  const Matrix6d compliance = elasticity_matrix(cast_iron).inverse();
  const double e = cast_iron.youngs_modulus, nu = cast_iron.poisson_ratio;
  EXPECT_NEAR(compliance(0, 0), 1.0 / e, 1e-12 / e);
  EXPECT_NEAR(compliance(1, 0), -nu / e, 1e-12 / e);
  EXPECT_NEAR(compliance(5, 5), 2.0 * (1.0 + nu) / e, 1e-12 / e);
  EXPECT_THROW(elasticity_matrix({1e11, 0.5, 1e-5}), core::SolverError);
  EXPECT_THROW(elasticity_matrix({-1.0, 0.3, 1e-5}), core::SolverError);
  EXPECT_THROW(stiffness_matrix(distorted_tet4(), {2e11, 0.7, 1e-5}, 0), core::SolverError);
}

TEST(Elasticity, StiffnessEqualsIntegralOfBtDB) {
  const Matrix6d d = elasticity_matrix(cast_iron);
  const Tet4Coords x4 = distorted_tet4();
  const ShapeGradients<4> g4 = tet4_gradients(x4, 0);
  const Eigen::Matrix<double, 6, 12> b4 = strain_displacement_matrix(g4.dn_dx);
  const Eigen::Matrix<double, 12, 12> k4 = b4.transpose() * d * b4 * (g4.det_j / 6.0);
  EXPECT_LT((stiffness_matrix(x4, cast_iron, 0) - k4).norm(), 1e-12 * k4.norm());
  // tet10, integrated independently with the degree-5 rule (exact for straight edges).
  const Tet10Coords x10 = straight_tet10(x4);
  const TetRule<14>& rule = tet_rule_degree5();
  Eigen::Matrix<double, 30, 30> k10 = Eigen::Matrix<double, 30, 30>::Zero();
  for (int q = 0; q < 14; ++q) {
    const ShapeGradients<10> g = tet10_gradients(x10, rule.points.col(q), 0);
    const Eigen::Matrix<double, 6, 30> b = strain_displacement_matrix(g.dn_dx);
    k10 += rule.weights(q) * g.det_j * b.transpose() * d * b;
  }
  EXPECT_LT((stiffness_matrix(x10, cast_iron, 0) - k10).norm(), 1e-12 * k10.norm());
}

/// Voigt strain (engineering shear) of the displacement gradient h.
Vector6d voigt_strain(const Eigen::Matrix3d& h) {
  Vector6d e;
  e << h(0, 0), h(1, 1), h(2, 2), h(1, 2) + h(2, 1), h(0, 2) + h(2, 0), h(0, 1) + h(1, 0);
  return e;
}

TEST(Elasticity, PatchTestLinearDisplacementGivesConstantStrainExactly) {
  Eigen::Matrix3d h;
  h << 2e-4, -1e-4, 3e-5,  //
      5e-5, -3e-4, 1e-4,   //
      -2e-5, 4e-5, 1.5e-4;
  const Eigen::Vector3d shift(1e-5, -2e-5, 3e-6);
  const auto field = [&](const Eigen::Vector3d& p) { return Eigen::Vector3d(h * p + shift); };
  const Vector6d expected = elasticity_matrix(cast_iron) * voigt_strain(h);
  const Eigen::Vector4d t_ref = Eigen::Vector4d::Constant(20.0);
  const Tet4Coords x4 = distorted_tet4();
  const Tet4Vector u4 = nodal_displacements<4>(x4, field);
  EXPECT_LT((strain_displacement_matrix(tet4_gradients(x4, 0).dn_dx) * u4 - voigt_strain(h)).norm(),
            1e-10 * voigt_strain(h).norm());
  const Eigen::Matrix<double, 6, 4> s4 = nodal_stresses(x4, cast_iron, u4, t_ref, 20.0, 0);
  for (int a = 0; a < 4; ++a) EXPECT_LT((s4.col(a) - expected).norm(), 1e-9 * expected.norm());
  for (const Tet10Coords& x : {straight_tet10(x4), curved_tet10()}) {
    const Tet10Vector u = nodal_displacements<10>(x, field);
    const Eigen::Matrix<double, 10, 1> t = Eigen::Matrix<double, 10, 1>::Constant(20.0);
    const Eigen::Matrix<double, 6, 10> s = nodal_stresses(x, cast_iron, u, t, 20.0, 0);
    for (int a = 0; a < 10; ++a) EXPECT_LT((s.col(a) - expected).norm(), 1e-9 * expected.norm());
    const Eigen::Vector3d xi(0.15, 0.3, 0.2);
    EXPECT_LT((stress_at(x, cast_iron, u, t, 20.0, xi, 0) - expected).norm(),
              1e-9 * expected.norm());
    EXPECT_LT(
        (strain_displacement_matrix(tet10_gradients(x, xi, 0).dn_dx) * u - voigt_strain(h)).norm(),
        1e-10 * voigt_strain(h).norm());
  }
}

TEST(Elasticity, FreeUniformThermalExpansionIsStressFree) {
  const double dt = 35.0, t_ref = 20.0;
  const double scale = cast_iron.youngs_modulus * cast_iron.thermal_expansion * dt;
  const Tet4Coords x4 = distorted_tet4();
  const Eigen::Vector3d origin = x4.col(2);
  const auto field = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector3d(cast_iron.thermal_expansion * dt * (p - origin));
  };
  const Tet4Vector u4 = nodal_displacements<4>(x4, field);
  const Eigen::Vector4d t4 = Eigen::Vector4d::Constant(t_ref + dt);
  const Tet4Vector f4 = thermal_load(x4, cast_iron, t4, t_ref, 0);
  EXPECT_GT(f4.norm(), 0.0);
  EXPECT_LT((stiffness_matrix(x4, cast_iron, 0) * u4 - f4).norm(), 1e-10 * f4.norm());
  EXPECT_LT(nodal_stresses(x4, cast_iron, u4, t4, t_ref, 0).norm(), 1e-9 * scale);
  for (const Tet10Coords& x : {straight_tet10(x4), curved_tet10()}) {
    const Tet10Vector u = nodal_displacements<10>(x, field);
    const Eigen::Matrix<double, 10, 1> t = Eigen::Matrix<double, 10, 1>::Constant(t_ref + dt);
    const Tet10Vector f = thermal_load(x, cast_iron, t, t_ref, 0);
    EXPECT_LT((stiffness_matrix(x, cast_iron, 0) * u - f).norm(), 1e-10 * f.norm());
    EXPECT_LT(nodal_stresses(x, cast_iron, u, t, t_ref, 0).norm(), 1e-9 * scale);
    EXPECT_LT(von_mises(stress_at(x, cast_iron, u, t, t_ref, Eigen::Vector3d(0.2, 0.2, 0.2), 0)),
              1e-9 * scale);
  }
  // The same displacement with no temperature rise is strongly (hydrostatically) stressed.
  EXPECT_GT(nodal_stresses(x4, cast_iron, u4, t4, t_ref + dt, 0).col(0).norm(), 0.5 * scale);
}

TEST(Elasticity, FreeExpansionUnderLinearTemperatureIsStressFreeOnTet10) {
  // T = T_ref + g . x is compatible: u_i = alpha ((g . x) x_i - |x|^2 g_i / 2) gives
  // epsilon = alpha (g . x) I, quadratic u that the straight tet10 represents exactly; the
  // degree-3 thermal load must then balance K u exactly.
  const double t_ref = 20.0;
  const double alpha = cast_iron.thermal_expansion;
  const Eigen::Vector3d g(400.0, -250.0, 600.0);  // [K/m]
  const Tet10Coords x = straight_tet10(distorted_tet4());
  const Eigen::Vector3d c = x.leftCols<4>().rowwise().mean();
  const Tet10Vector u = nodal_displacements<10>(x, [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d y = p - c;
    return Eigen::Vector3d(alpha * (g.dot(y) * y - 0.5 * y.squaredNorm() * g));
  });
  Eigen::Matrix<double, 10, 1> t;
  for (int a = 0; a < 10; ++a) t(a) = t_ref + 30.0 + g.dot(x.col(a) - c);
  const Tet10Vector f = thermal_load(x, cast_iron, t, t_ref + 30.0, 0);
  EXPECT_GT(f.norm(), 0.0);
  EXPECT_LT((stiffness_matrix(x, cast_iron, 0) * u - f).norm(), 1e-10 * f.norm());
  const double scale = cast_iron.youngs_modulus * alpha * (g.norm() * 0.03);
  EXPECT_LT(nodal_stresses(x, cast_iron, u, t, t_ref + 30.0, 0).norm(), 1e-8 * scale);
}

TEST(Elasticity, Tet10ThermalLoadIsExactForQuadraticTemperature) {
  const Tet10Coords x = straight_tet10(distorted_tet4());
  Eigen::Matrix<double, 10, 1> t;
  t << 300, 310, 295, 320, 312, 301, 299, 305, 318, 307;
  const double t_ref = 293.15;
  const double beta = cast_iron.youngs_modulus / (1.0 - 2.0 * cast_iron.poisson_ratio);
  const TetRule<14>& rule = tet_rule_degree5();
  Eigen::Matrix<double, 3, 10> expected = Eigen::Matrix<double, 3, 10>::Zero();
  for (int q = 0; q < 14; ++q) {
    const Eigen::Vector3d xi = rule.points.col(q);
    const ShapeGradients<10> g = tet10_gradients(x, xi, 0);
    const double dt = tet10_shape(xi).dot(t) - t_ref;
    expected +=
        rule.weights(q) * g.det_j * beta * cast_iron.thermal_expansion * dt * g.dn_dx.transpose();
  }
  const Tet10Vector f = thermal_load(x, cast_iron, t, t_ref, 0);
  EXPECT_LT((f - Eigen::Map<const Tet10Vector>(expected.data())).norm(), 1e-12 * f.norm());
  // The net force of a self-equilibrated thermal load is zero.
  for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(f(Eigen::seqN(k, 10, 3)).sum()), 1e-9 * f.norm());
}

TEST(Elasticity, ThermalCouplingMatrixReproducesThermalLoad) {
  const double t_ref = 293.15;
  const Tet4Coords x4 = distorted_tet4();
  const Eigen::Vector4d t4(300.0, 340.0, 295.0, 320.0);
  const Tet4Vector f4 = thermal_load(x4, cast_iron, t4, t_ref, 0);
  const Eigen::Matrix<double, 12, 4> g4 = thermal_coupling_matrix(x4, cast_iron, 0);
  EXPECT_LT((g4 * (t4 - Eigen::Vector4d::Constant(t_ref)) - f4).norm(), 1e-12 * f4.norm());
  Eigen::Matrix<double, 10, 1> t;
  t << 300, 340, 295, 320, 312, 301, 299, 305, 318, 307;
  for (const Tet10Coords& x : {straight_tet10(x4), curved_tet10()}) {
    const Tet10Vector f = thermal_load(x, cast_iron, t, t_ref, 0);
    const Eigen::Matrix<double, 30, 10> g = thermal_coupling_matrix(x, cast_iron, 0);
    const Eigen::Matrix<double, 10, 1> dt = t - Eigen::Matrix<double, 10, 1>::Constant(t_ref);
    EXPECT_GT(f.norm(), 0.0);
    EXPECT_LT((g * dt - f).norm(), 1e-12 * f.norm());
  }
}

TEST(Elasticity, VonMises) {
  Vector6d s = Vector6d::Zero();
  s(0) = -150e6;
  EXPECT_NEAR(von_mises(s), 150e6, 1e-6);
  s << 0, 0, 0, 0, 0, 40e6;
  EXPECT_NEAR(von_mises(s), std::sqrt(3.0) * 40e6, 1e-6);
  s << 70e6, 70e6, 70e6, 0, 0, 0;
  EXPECT_NEAR(von_mises(s), 0.0, 1e-6);
}

TEST(Elasticity, SameElementInMillimetresGivesSameSiResult) {
  // One tet10 held isostatically (3-2-1 on corners 0, 1, 2) under a non-uniform temperature.
  // In mm with E in N/mm^2 the displacements come out in mm and stresses in N/mm^2 = MPa.
  Eigen::Matrix<double, 10, 1> t;
  t << 300, 340, 295, 320, 312, 301, 299, 305, 318, 307;
  const double t_ref = 293.15;
  const auto solve = [&](const Tet10Coords& x, double pascal_unit) {
    ElasticMaterial m = cast_iron;
    m.youngs_modulus = cast_iron.youngs_modulus / pascal_unit;
    Eigen::Matrix<double, 30, 30> k = stiffness_matrix(x, m, 0);
    Tet10Vector f = thermal_load(x, m, t, t_ref, 0);
    for (const int dof : {0, 1, 2, 4, 5, 8}) {
      k.row(dof).setZero();
      k.col(dof).setZero();
      k(dof, dof) = 1.0;
      f(dof) = 0.0;
    }
    const Tet10Vector u = k.fullPivLu().solve(f);
    return std::make_pair(u, Eigen::Matrix<double, 6, 10>(nodal_stresses(x, m, u, t, t_ref, 0)));
  };
  const Tet10Coords x_m = curved_tet10();
  const auto [u_m, s_m] = solve(x_m, 1.0);
  const auto [u_mm, s_mm] = solve(1000.0 * x_m, 1e6);
  EXPECT_GT(u_m.norm(), 1e-7);
  EXPECT_GT(s_m.norm(), 1e3) << "non-uniform temperature must stress the element";
  EXPECT_LT((1e-3 * u_mm - u_m).norm(), 1e-8 * u_m.norm());
  EXPECT_LT((1e6 * s_mm - s_m).norm(), 1e-8 * s_m.norm());
}

}  // namespace
}  // namespace tt::solvers::kernels
