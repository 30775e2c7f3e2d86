// Spatial order of the conduction operator with a manufactured steady solution
//   u = sin(2x + y) exp(z / 2) + x^2 on the unit cube, k = 1 W/(m K), q = -k lap u,
// from the assembled K of thermal_system, a load vector built here from the kernels' shape
// functions and degree-5 quadrature, and u prescribed at every boundary node by elimination. The
// L2 error, by the same quadrature, should fall as h^2 on 4-node and h^3 on 10-node tets, with
// h = (volume / #tets)^(1/3) measured on the meshes TetGen makes for four max_edge levels.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <cstdio>

#include "solvers/kernels/element.hpp"
#include "solvers/kernels/quadrature.hpp"
#include "tests/thermal/thermal_fixtures.hpp"

namespace tt::thermal_test {
namespace {

namespace kn = solvers::kernels;

double exact_u(const Eigen::Vector3d& p) {
  return std::sin(2 * p.x() + p.y()) * std::exp(0.5 * p.z()) + p.x() * p.x();
}
/// -k lap u with k = 1 [W/m^3].
double source_q(const Eigen::Vector3d& p) {
  return 4.75 * std::sin(2 * p.x() + p.y()) * std::exp(0.5 * p.z()) - 2.0;
}

/// Shape functions and |det J| of element `t` at natural point xi.
template <int N>
std::pair<Eigen::Matrix<double, N, 1>, double> shape_and_det(const Eigen::Matrix<double, 3, N>& x,
                                                             const Eigen::Vector3d& xi) {
  if constexpr (N == 4) {
    return {kn::tet4_shape(xi), std::abs(kn::jacobian(x).determinant())};
  } else {
    return {kn::tet10_shape(xi), std::abs(kn::jacobian(x, xi).determinant())};
  }
}

struct MmsResult {
  double h = 0, l2 = 0;
  int nodes = 0;
};

template <int N>
MmsResult mms_error(double max_edge) {
  BoxCase cube;
  cube.max_edge = max_edge;
  cube.order = N == 4 ? 1 : 2;
  cube.conductivity = 1.0;
  cube.extra =
      "[thermal]\nstep_s = 1.0\n[duty_cycle]\nend_s = 1.0\n"
      "segments = [ { start_s = 0.0, speed_rpm = 0.0 } ]\n";
  const auto spec = case_of(cube.toml());
  const mesh::TetMesh mesh = mesh::mesh_case(spec);
  EXPECT_EQ(mesh.nodes_per_tet(), N);
  const Eigen::SparseMatrix<double> k = solvers::thermal_system(mesh, spec).conduction;
  const int n = static_cast<int>(mesh.nodes.rows()), nt = static_cast<int>(mesh.tets.rows());
  const auto& rule = kn::tet_rule_degree5();
  auto coords = [&](int t) {
    Eigen::Matrix<double, 3, N> x;
    for (int a = 0; a < N; ++a) x.col(a) = mesh.nodes.row(mesh.tets(t, a)).transpose();
    return x;
  };

  Eigen::VectorXd load = Eigen::VectorXd::Zero(n);
  for (int t = 0; t < nt; ++t) {
    const auto x = coords(t);
    for (int q = 0; q < rule.points.cols(); ++q) {
      const auto [shape, det] = shape_and_det<N>(x, rule.points.col(q));
      const Eigen::Vector3d p = x * shape;
      for (int a = 0; a < N; ++a)
        load(mesh.tets(t, a)) += rule.weights(q) * det * source_q(p) * shape(a);
    }
  }

  // Dirichlet by elimination: interior unknowns numbered 0..ni-1, boundary values exact.
  std::vector<bool> on_boundary(n, false);
  for (int f = 0; f < mesh.faces.rows(); ++f)
    if (mesh.face_other_tet[f] < 0)
      for (int a = 0; a < mesh.nodes_per_face(); ++a) on_boundary[mesh.faces(f, a)] = true;
  std::vector<int> unknown(n, -1);
  int ni = 0;
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    if (on_boundary[i])
      u(i) = exact_u(mesh.nodes.row(i).transpose());
    else
      unknown[i] = ni++;
  }
  EXPECT_GT(ni, 0);
  std::vector<Eigen::Triplet<double>> kii;
  Eigen::VectorXd rhs(ni);
  for (int i = 0; i < n; ++i)
    if (unknown[i] >= 0) rhs(unknown[i]) = load(i);
  for (int col = 0; col < k.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(k, col); it; ++it) {
      const int r = static_cast<int>(it.row());
      if (unknown[r] < 0) continue;
      if (unknown[col] >= 0)
        kii.emplace_back(unknown[r], unknown[col], it.value());
      else
        rhs(unknown[r]) -= it.value() * u(col);
    }
  Eigen::SparseMatrix<double> a(ni, ni);
  a.setFromTriplets(kii.begin(), kii.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(a);
  EXPECT_EQ(solver.info(), Eigen::Success);
  const Eigen::VectorXd ui = solver.solve(rhs);
  for (int i = 0; i < n; ++i)
    if (unknown[i] >= 0) u(i) = ui(unknown[i]);

  double err2 = 0, volume = 0;
  for (int t = 0; t < nt; ++t) {
    const auto x = coords(t);
    Eigen::Matrix<double, N, 1> ue;
    for (int a = 0; a < N; ++a) ue(a) = u(mesh.tets(t, a));
    for (int q = 0; q < rule.points.cols(); ++q) {
      const auto [shape, det] = shape_and_det<N>(x, rule.points.col(q));
      const double e = shape.dot(ue) - exact_u(x * shape);
      err2 += rule.weights(q) * det * e * e;
      volume += rule.weights(q) * det;
    }
  }
  EXPECT_NEAR(volume, 1.0, 1e-12);
  return {std::cbrt(volume / nt), std::sqrt(err2), n};
}

/// Least-squares slope of log(error) against log(h): the observed order over all levels.
double fitted_order(const std::vector<MmsResult>& runs) {
  double mx = 0, my = 0;
  for (const auto& r : runs) mx += std::log(r.h) / runs.size(), my += std::log(r.l2) / runs.size();
  double sxy = 0, sxx = 0;
  for (const auto& r : runs) {
    sxy += (std::log(r.h) - mx) * (std::log(r.l2) - my);
    sxx += (std::log(r.h) - mx) * (std::log(r.h) - mx);
  }
  return sxy / sxx;
}

// TetGen's meshes at successive max_edge differ in shape as well as size, so the order between
// two neighbouring levels (h ratio about 1.4) scatters by +-0.5 (measured on tet10: 3.08, 2.85,
// 3.50); the fit over four levels is the observed order asserted within +-0.3, each pair
// within +-0.6.
template <int N>
void check_order(const std::vector<double>& levels, double expected) {
  std::vector<MmsResult> runs;
  for (double max_edge : levels) {
    runs.push_back(mms_error<N>(max_edge));
    std::printf("[space order] tet%d max_edge %.2f: %d nodes, h %.4f m, L2 error %.3e\n", N,
                max_edge, runs.back().nodes, runs.back().h, runs.back().l2);
  }
  for (size_t i = 1; i < runs.size(); ++i) {
    const double p = observed_order(runs[i - 1].h, runs[i - 1].l2, runs[i].h, runs[i].l2);
    std::printf("[space order] tet%d L2 order between levels %zu and %zu: %.3f\n", N, i - 1, i, p);
    EXPECT_NEAR(p, expected, 0.6) << "between max_edge levels " << i - 1 << " and " << i;
  }
  const double p = fitted_order(runs);
  std::printf("[space order] tet%d fitted L2 order %.3f\n", N, p);
  EXPECT_NEAR(p, expected, 0.3);
}

TEST(ThermalSpaceOrder, LinearTetsSecondOrderInL2) {
  check_order<4>({0.3, 0.2, 0.14, 0.1}, 2.0);
}

TEST(ThermalSpaceOrder, QuadraticTetsThirdOrderInL2) {
  check_order<10>({0.35, 0.25, 0.18, 0.13}, 3.0);
}

}  // namespace
}  // namespace tt::thermal_test
