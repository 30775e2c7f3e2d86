// Heat-conduction kernels: algebraic properties, exact values on reference elements, patch tests,
// energy integrals and unit scaling.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "core/errors.hpp"
#include "solvers/kernels/heat.hpp"
#include "tests/kernels/fixtures.hpp"

namespace tt::solvers::kernels {
namespace {

using testing::curved_tet10;
using testing::distorted_tet4;
using testing::reference_tet4;
using testing::straight_tet10;

constexpr double k_cast_iron = 45.0;       // [W/(m K)]
constexpr double rho_c_cast_iron = 3.9e6;  // [J/(m^3 K)]

template <int N>
void expect_symmetric_psd_with_one_zero_mode(const Eigen::Matrix<double, N, N>& k) {
  EXPECT_LT((k - k.transpose()).norm(), 1e-14 * k.norm());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(k);
  const Eigen::Matrix<double, N, 1> lambda = eig.eigenvalues();  // ascending
  EXPECT_GT(lambda(N - 1), 0.0);
  EXPECT_LT(std::abs(lambda(0)), 1e-12 * lambda(N - 1));
  EXPECT_GT(lambda(1), 1e-6 * lambda(N - 1)) << "more than one zero mode";
  EXPECT_LT((k * Eigen::Matrix<double, N, 1>::Ones()).norm(), 1e-12 * k.norm());
}

TEST(Heat, ConductivitySymmetricPsdConstantInNullSpace) {
  expect_symmetric_psd_with_one_zero_mode<4>(conductivity_matrix(distorted_tet4(), k_cast_iron, 0));
  expect_symmetric_psd_with_one_zero_mode<10>(
      conductivity_matrix(straight_tet10(distorted_tet4()), k_cast_iron, 0));
  expect_symmetric_psd_with_one_zero_mode<10>(conductivity_matrix(curved_tet10(), k_cast_iron, 0));
}

TEST(Heat, Tet4ConductivityOnReferenceTet) {
  // V = 1/6, gradients (-1,-1,-1), e_x, e_y, e_z: K = V G G^T.
  const Eigen::Matrix4d k = conductivity_matrix(reference_tet4(), 6.0, 0);
  Eigen::Matrix4d expected;
  expected << 3, -1, -1, -1,  //
      -1, 1, 0, 0,            //
      -1, 0, 1, 0,            //
      -1, 0, 0, 1;
  EXPECT_LT((k - expected).norm(), 1e-14);
}

/// Nodal values of T = t0 + g . x.
template <int N>
Eigen::Matrix<double, N, 1> linear_field(const Eigen::Matrix<double, 3, N>& x, double t0,
                                         const Eigen::Vector3d& g) {
  return (Eigen::Matrix<double, N, 1>::Constant(t0) + x.transpose() * g).eval();
}

TEST(Heat, PatchTestLinearTemperatureGivesExactConstantFlux) {
  const Eigen::Vector3d g(120.0, -45.0, 80.0);  // [K/m]
  const Eigen::Vector3d expected = -k_cast_iron * g;
  const Tet4Coords x4 = distorted_tet4();
  EXPECT_LT((heat_flux_at(x4, k_cast_iron, linear_field<4>(x4, 293.0, g), 0) - expected).norm(),
            1e-10 * expected.norm());
  for (const Tet10Coords& x : {straight_tet10(x4), curved_tet10()}) {
    const Eigen::Matrix<double, 10, 1> t = linear_field<10>(x, 293.0, g);
    for (const Eigen::Vector3d& xi :
         {Eigen::Vector3d(0.25, 0.25, 0.25), Eigen::Vector3d(0.0, 0.0, 0.0),
          Eigen::Vector3d(0.6, 0.1, 0.2), Eigen::Vector3d(0.0, 0.5, 0.5)}) {
      EXPECT_LT((heat_flux_at(x, k_cast_iron, t, xi, 0) - expected).norm(),
                1e-10 * expected.norm());
    }
  }
}

/// Nodal loads of a uniform inward flux -k g . n on every face: for a linear T, K T must equal
/// them (the divergence theorem with div grad T = 0).
template <int N, int F, class Faces>
Eigen::Matrix<double, N, 1> boundary_flux_loads(const Eigen::Matrix<double, 3, N>& x,
                                                const Faces& faces, const Eigen::Vector3d& g) {
  Eigen::Matrix<double, N, 1> f = Eigen::Matrix<double, N, 1>::Zero();
  for (int k = 0; k < 4; ++k) {
    Eigen::Matrix<double, 3, F> face;
    for (int i = 0; i < F; ++i) face.col(i) = x.col(faces[k][i]);
    // Heat flowing in through the face: k grad T . n (n outward).
    const Eigen::Matrix<double, F, 1> fk =
        flux_load(face, k_cast_iron * g.dot(face_normal(face, k)), k);
    for (int i = 0; i < F; ++i) f(faces[k][i]) += fk(i);
  }
  return f;
}

TEST(Heat, ConductivityTimesLinearFieldEqualsBoundaryFlux) {
  const Eigen::Vector3d g(120.0, -45.0, 80.0);
  const Tet4Coords x4 = distorted_tet4();
  const Eigen::Vector4d f4 = boundary_flux_loads<4, 3>(x4, tet4_faces, g);
  EXPECT_LT((conductivity_matrix(x4, k_cast_iron, 0) * linear_field<4>(x4, 10.0, g) - f4).norm(),
            1e-10 * f4.norm());
  const Tet10Coords x10 = straight_tet10(x4);
  const Eigen::Matrix<double, 10, 1> f10 = boundary_flux_loads<10, 6>(x10, tet10_faces, g);
  EXPECT_LT(
      (conductivity_matrix(x10, k_cast_iron, 0) * linear_field<10>(x10, 10.0, g) - f10).norm(),
      1e-10 * f10.norm());
}

TEST(Heat, CapacitySumsToRhoCVAndLumpedIsPositive) {
  const Tet4Coords x4 = distorted_tet4();
  const double v = element_volume(x4, 0);
  EXPECT_NEAR(v, jacobian(x4).determinant() / 6.0, 1e-15 * v);
  const double total = rho_c_cast_iron * v;
  const Eigen::Matrix4d m4 = capacity_matrix(x4, rho_c_cast_iron, 0);
  EXPECT_NEAR(m4.sum(), total, 1e-12 * total);
  EXPECT_NEAR(m4(0, 0), total / 10.0, 1e-12 * total);
  EXPECT_NEAR(m4(0, 1), total / 20.0, 1e-12 * total);
  const Eigen::Vector4d l4 = lumped_capacity(x4, rho_c_cast_iron, 0);
  EXPECT_NEAR(l4.sum(), total, 1e-12 * total);
  EXPECT_LT((l4 - m4.rowwise().sum()).norm(), 1e-12 * total);

  for (const Tet10Coords& x : {straight_tet10(x4), curved_tet10()}) {
    const double v10 = element_volume(x, 0);
    const Eigen::Matrix<double, 10, 10> m = capacity_matrix(x, rho_c_cast_iron, 0);
    EXPECT_NEAR(m.sum(), rho_c_cast_iron * v10, 1e-12 * total);
    EXPECT_LT((m - m.transpose()).norm(), 1e-14 * m.norm());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 10, 10>> eig(m);
    EXPECT_GT(eig.eigenvalues()(0), 0.0) << "consistent capacity must be positive definite";
    const Eigen::Matrix<double, 10, 1> l = lumped_capacity(x, rho_c_cast_iron, 0);
    EXPECT_NEAR(l.sum(), rho_c_cast_iron * v10, 1e-12 * total);
    EXPECT_GT(l.minCoeff(), 0.0);
    // Row sums would give negative corner masses: the reason for HRZ.
    EXPECT_LT(m.rowwise().sum().head<4>().maxCoeff(), 0.0);
  }
  // Straight tet10: v equals the corners' volume; consistent diagonal V/70 and 8V/105, HRZ
  // corners V/36 and mid-edge nodes 4V/27.
  const Tet10Coords x10 = straight_tet10(x4);
  EXPECT_NEAR(element_volume(x10, 0), v, 1e-13 * v);
  const Eigen::Matrix<double, 10, 10> m10 = capacity_matrix(x10, rho_c_cast_iron, 0);
  const Eigen::Matrix<double, 10, 1> l10 = lumped_capacity(x10, rho_c_cast_iron, 0);
  for (int a = 0; a < 10; ++a) {
    EXPECT_NEAR(m10(a, a), total * (a < 4 ? 1.0 / 70.0 : 8.0 / 105.0), 1e-12 * total);
    EXPECT_NEAR(l10(a), total * (a < 4 ? 1.0 / 36.0 : 4.0 / 27.0), 1e-12 * total);
    EXPECT_NEAR(m10.row(a).sum(), total * (a < 4 ? -1.0 / 20.0 : 1.0 / 5.0), 1e-12 * total);
  }
}

TEST(Heat, SourceVectorSumsToQV) {
  const double q = 2.5e5;  // [W/m^3]
  const Tet4Coords x4 = distorted_tet4();
  const double v = element_volume(x4, 0);
  EXPECT_LT((source_vector(x4, q, 0) - Eigen::Vector4d::Constant(q * v / 4.0)).norm(),
            1e-12 * q * v);
  const Eigen::Matrix<double, 10, 1> f = source_vector(straight_tet10(x4), q, 0);
  for (int a = 0; a < 10; ++a) EXPECT_NEAR(f(a), q * v * (a < 4 ? -0.05 : 0.2), 1e-12 * q * v);
  const Tet10Coords curved = curved_tet10();
  EXPECT_NEAR(source_vector(curved, q, 0).sum(), q * element_volume(curved, 0), 1e-12 * q * v);
}

TEST(Heat, StoredHeatMatchesCapacityMatrix) {
  // integral rho c (T - T0) = 1^T M (T - T0) since the shape functions sum to one.
  const Tet4Coords x4 = distorted_tet4();
  const Eigen::Vector4d t4(300.0, 310.0, 295.0, 320.0);
  const double e4 = stored_heat(x4, rho_c_cast_iron, t4, 293.15, 0);
  const Eigen::Vector4d dt4 = t4 - Eigen::Vector4d::Constant(293.15);
  EXPECT_NEAR(e4, (capacity_matrix(x4, rho_c_cast_iron, 0) * dt4).sum(), 1e-12 * std::abs(e4));
  EXPECT_GT(e4, 0.0);
  for (const Tet10Coords& x : {straight_tet10(x4), curved_tet10()}) {
    Eigen::Matrix<double, 10, 1> t;
    t << 300, 310, 295, 320, 312, 301, 299, 305, 318, 307;
    const double e = stored_heat(x, rho_c_cast_iron, t, 293.15, 0);
    const Eigen::Matrix<double, 10, 1> dt = t - Eigen::Matrix<double, 10, 1>::Constant(293.15);
    EXPECT_NEAR(e, (capacity_matrix(x, rho_c_cast_iron, 0) * dt).sum(), 1e-12 * std::abs(e));
    // Uniform T: rho c V dT exactly.
    EXPECT_NEAR(
        stored_heat(x, rho_c_cast_iron, Eigen::Matrix<double, 10, 1>::Constant(303.15), 293.15, 0),
        rho_c_cast_iron * element_volume(x, 0) * 10.0, 1e-12 * std::abs(e));
  }
}

TEST(Heat, ConvectionKernelsAgreeWithHeatRate) {
  const double h = 12.0;       // [W/(m^2 K)]
  const double sink = 293.15;  // [K]
  Tri3Coords t;
  t << 0.0, 0.03, 0.004,  //
      0.0, 0.001, 0.02,   //
      0.1, 0.102, 0.097;
  const double area = face_area(t);
  const Eigen::Matrix3d c3 = convection_matrix(t, h, 0);
  EXPECT_NEAR(c3.sum(), h * area, 1e-14 * h * area);
  EXPECT_NEAR(c3(0, 0), h * area / 6.0, 1e-14 * h * area);
  const Eigen::Vector3d f3 = convection_load(t, h, sink, 0);
  EXPECT_NEAR(f3.sum(), h * sink * area, 1e-12 * h * sink * area);
  EXPECT_NEAR(flux_load(t, 500.0, 0).sum(), 500.0 * area, 1e-12 * 500.0 * area);
  const Eigen::Vector3d temps(310.0, 330.0, 300.0);
  const double rate3 = convected_heat_rate(t, h, temps, sink, 0);
  EXPECT_NEAR(rate3, h * area * (temps.mean() - sink), 1e-12 * std::abs(rate3));
  EXPECT_NEAR(rate3, (c3 * temps - f3).sum(), 1e-9 * std::abs(rate3));

  Tri6Coords s;
  s.leftCols<3>() = t;
  for (int e = 0; e < 3; ++e) s.col(3 + e) = 0.5 * (t.col(e) + t.col((e + 1) % 3));
  const Eigen::Matrix<double, 6, 6> c6 = convection_matrix(s, h, 0);
  EXPECT_LT((c6 - c6.transpose()).norm(), 1e-14 * c6.norm());
  EXPECT_NEAR(c6.sum(), h * area, 1e-13 * h * area);
  const Eigen::Matrix<double, 6, 1> f6 = convection_load(s, h, sink, 0);
  for (int a = 0; a < 6; ++a)
    EXPECT_NEAR(f6(a), a < 3 ? 0.0 : h * sink * area / 3.0, 1e-12 * h * sink * area);
  Tri6Coords bulged = s;
  bulged(2, 4) += 0.002;
  for (const Tri6Coords& face : {s, bulged}) {
    Eigen::Matrix<double, 6, 1> t6;
    t6 << 310, 330, 300, 325, 315, 305;
    const double rate6 = convected_heat_rate(face, h, t6, sink, 0);
    EXPECT_NEAR(rate6,
                (convection_matrix(face, h, 0) * t6 - convection_load(face, h, sink, 0)).sum(),
                1e-9 * std::abs(rate6));
    EXPECT_GT(rate6, 0.0);
  }
}

TEST(Heat, SameElementInMillimetresGivesSameSiResult) {
  // Steady state of one element: a heat source, convection on face 3 (opposite corner 3).
  // In mm, k is in W/(mm K), h in W/(mm^2 K), q in W/mm^3: the temperatures must agree.
  const double k = k_cast_iron, h = 25.0, q = 4.0e5, sink = 20.0;
  const auto steady = [&](const Tet10Coords& x, double length_unit) {
    const double kk = k * length_unit, hh = h * length_unit * length_unit,
                 qq = q * length_unit * length_unit * length_unit;
    Eigen::Matrix<double, 10, 10> a = conductivity_matrix(x, kk, 0);
    Eigen::Matrix<double, 10, 1> b = source_vector(x, qq, 0);
    Tri6Coords face;
    for (int i = 0; i < 6; ++i) face.col(i) = x.col(tet10_faces[3][i]);
    const Eigen::Matrix<double, 6, 6> c = convection_matrix(face, hh, 3);
    const Eigen::Matrix<double, 6, 1> f = convection_load(face, hh, sink, 3);
    for (int i = 0; i < 6; ++i) {
      b(tet10_faces[3][i]) += f(i);
      for (int j = 0; j < 6; ++j) a(tet10_faces[3][i], tet10_faces[3][j]) += c(i, j);
    }
    return Eigen::Matrix<double, 10, 1>(a.fullPivLu().solve(b));
  };
  const Tet10Coords x_m = curved_tet10();
  const Tet10Coords x_mm = 1000.0 * x_m;
  const Eigen::Matrix<double, 10, 1> t_m = steady(x_m, 1.0);
  const Eigen::Matrix<double, 10, 1> t_mm = steady(x_mm, 1e-3);
  EXPECT_GT(t_m.minCoeff(), sink + 1e-3) << "the source must heat the element";
  EXPECT_LT((t_mm - t_m).norm(), 1e-9 * t_m.norm());
  // Matrices scale as length (conductivity) and length^3 (capacity).
  EXPECT_LT((conductivity_matrix(x_mm, k, 0) - 1e3 * conductivity_matrix(x_m, k, 0)).norm(),
            1e-10 * 1e3 * conductivity_matrix(x_m, k, 0).norm());
  EXPECT_NEAR(capacity_matrix(x_mm, rho_c_cast_iron, 0).sum(),
              1e9 * capacity_matrix(x_m, rho_c_cast_iron, 0).sum(),
              1e-10 * 1e9 * capacity_matrix(x_m, rho_c_cast_iron, 0).sum());
}

TEST(Heat, DegenerateFaceThrows) {
  Tri3Coords t = Tri3Coords::Zero();
  t(0, 1) = 0.01;
  EXPECT_THROW(convection_matrix(t, 10.0, 7), core::SolverError);
  Tri6Coords s = Tri6Coords::Zero();
  EXPECT_THROW(flux_load(s, 10.0, 7), core::SolverError);
}

}  // namespace
}  // namespace tt::solvers::kernels
