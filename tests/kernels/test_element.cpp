// Shape functions, Jacobians, point location and face geometry.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <string>

#include "core/errors.hpp"
#include "solvers/kernels/element.hpp"
#include "solvers/kernels/heat.hpp"
#include "solvers/kernels/quadrature.hpp"
#include "tests/kernels/fixtures.hpp"

namespace tt::solvers::kernels {
namespace {

using testing::curved_tet10;
using testing::distorted_tet4;
using testing::reference_tet4;
using testing::straight_tet10;

/// A few interior and boundary natural points.
std::vector<Eigen::Vector3d> sample_points() {
  return {Eigen::Vector3d(0.25, 0.25, 0.25), Eigen::Vector3d(0.1, 0.2, 0.3),
          Eigen::Vector3d(0.7, 0.05, 0.1),   Eigen::Vector3d(0.0, 0.5, 0.5),
          Eigen::Vector3d(0.3, 0.0, 0.0),    Eigen::Vector3d(0.05, 0.05, 0.85)};
}

TEST(Shape, Tet10NodesFollowVtkOrder) {
  const Eigen::Matrix<double, 3, 10> nodes = tet10_node_natural();
  // Corners: 0 at the origin, 1 at r = 1, 2 at s = 1, 3 at t = 1.
  EXPECT_TRUE(nodes.leftCols<4>().isApprox(reference_tet4()));
  // Mid-edge nodes 4..9 on (0,1) (1,2) (0,2) (0,3) (1,3) (2,3).
  const int edges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  for (int e = 0; e < 6; ++e) {
    const Eigen::Vector3d mid = 0.5 * (nodes.col(edges[e][0]) + nodes.col(edges[e][1]));
    EXPECT_LT((nodes.col(4 + e) - mid).norm(), 1e-15) << "node " << 4 + e;
  }
  // Explicit values, so a consistent mistake in tet_edges also fails.
  EXPECT_TRUE(nodes.col(4).isApprox(Eigen::Vector3d(0.5, 0, 0)));
  EXPECT_TRUE(nodes.col(5).isApprox(Eigen::Vector3d(0.5, 0.5, 0)));
  EXPECT_TRUE(nodes.col(6).isApprox(Eigen::Vector3d(0, 0.5, 0)));
  EXPECT_TRUE(nodes.col(7).isApprox(Eigen::Vector3d(0, 0, 0.5)));
  EXPECT_TRUE(nodes.col(8).isApprox(Eigen::Vector3d(0.5, 0, 0.5)));
  EXPECT_TRUE(nodes.col(9).isApprox(Eigen::Vector3d(0, 0.5, 0.5)));
}

TEST(Shape, KroneckerDeltaAtNodes) {
  const Eigen::Matrix<double, 3, 10> nodes = tet10_node_natural();
  for (int a = 0; a < 10; ++a) {
    const Eigen::Matrix<double, 10, 1> n = tet10_shape(nodes.col(a));
    for (int b = 0; b < 10; ++b) EXPECT_NEAR(n(b), a == b ? 1.0 : 0.0, 1e-15);
  }
  for (int a = 0; a < 4; ++a) {
    const Eigen::Vector4d n = tet4_shape(nodes.col(a));
    for (int b = 0; b < 4; ++b) EXPECT_NEAR(n(b), a == b ? 1.0 : 0.0, 1e-15);
  }
  Eigen::Matrix<double, 2, 6> tri_nodes;
  tri_nodes << 0, 1, 0, 0.5, 0.5, 0,  //
      0, 0, 1, 0, 0.5, 0.5;
  for (int a = 0; a < 6; ++a) {
    const Eigen::Matrix<double, 6, 1> n = tri6_shape(tri_nodes.col(a));
    for (int b = 0; b < 6; ++b) EXPECT_NEAR(n(b), a == b ? 1.0 : 0.0, 1e-15);
  }
}

TEST(Shape, PartitionOfUnityAndZeroDerivativeSum) {
  for (const Eigen::Vector3d& xi : sample_points()) {
    EXPECT_NEAR(tet4_shape(xi).sum(), 1.0, 1e-15);
    EXPECT_NEAR(tet10_shape(xi).sum(), 1.0, 1e-14);
    EXPECT_LT(tet10_shape_derivatives(xi).colwise().sum().norm(), 1e-14);
    const Eigen::Vector2d rs = xi.head<2>() * 0.9;
    EXPECT_NEAR(tri6_shape(rs).sum(), 1.0, 1e-15);
    EXPECT_LT(tri6_shape_derivatives(rs).colwise().sum().norm(), 1e-14);
  }
  EXPECT_LT(tet4_shape_derivatives().colwise().sum().norm(), 1e-15);
}

TEST(Shape, DerivativesMatchFiniteDifferences) {
  const double h = 1e-6;
  for (const Eigen::Vector3d& xi : sample_points()) {
    const Eigen::Matrix<double, 10, 3> d = tet10_shape_derivatives(xi);
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(j);
      const Eigen::Matrix<double, 10, 1> fd =
          (tet10_shape(xi + step) - tet10_shape(xi - step)) / (2 * h);
      EXPECT_LT((fd - d.col(j)).norm(), 1e-8) << "dxi_" << j;
    }
    const Eigen::Vector2d rs = xi.head<2>() * 0.9;
    const Eigen::Matrix<double, 6, 2> dt = tri6_shape_derivatives(rs);
    for (int j = 0; j < 2; ++j) {
      const Eigen::Vector2d step = h * Eigen::Vector2d::Unit(j);
      const Eigen::Matrix<double, 6, 1> fd =
          (tri6_shape(rs + step) - tri6_shape(rs - step)) / (2 * h);
      EXPECT_LT((fd - dt.col(j)).norm(), 1e-8);
    }
  }
}

/// A full quadratic in x, y, z.
double quadratic(const Eigen::Vector3d& p) {
  return 1.5 - 2.0 * p.x() + 0.7 * p.y() + 3.0 * p.z() + 4.0 * p.x() * p.x() - 1.2 * p.y() * p.y() +
         0.8 * p.z() * p.z() + 2.5 * p.x() * p.y() - 1.7 * p.y() * p.z() + 0.9 * p.x() * p.z();
}
Eigen::Vector3d quadratic_gradient(const Eigen::Vector3d& p) {
  return {-2.0 + 8.0 * p.x() + 2.5 * p.y() + 0.9 * p.z(),
          0.7 - 2.4 * p.y() + 2.5 * p.x() - 1.7 * p.z(),
          3.0 + 1.6 * p.z() - 1.7 * p.y() + 0.9 * p.x()};
}

TEST(Shape, StraightTet10InterpolatesQuadraticsExactly) {
  // Scaled so that the quadratic's terms are all of order one.
  const Tet10Coords x = straight_tet10(distorted_tet4() * 10.0);
  Eigen::Matrix<double, 10, 1> f;
  for (int a = 0; a < 10; ++a) f(a) = quadratic(x.col(a));
  for (const Eigen::Vector3d& xi : sample_points()) {
    const Eigen::Vector3d p = x * tet10_shape(xi);
    EXPECT_NEAR(tet10_shape(xi).dot(f), quadratic(p), 1e-12);
    const ShapeGradients<10> g = tet10_gradients(x, xi, 0);
    EXPECT_LT((g.dn_dx.transpose() * f - quadratic_gradient(p)).norm(), 1e-11);
  }
}

TEST(Shape, JacobianOfReferenceAndScaledTet) {
  EXPECT_TRUE(jacobian(reference_tet4()).isApprox(Eigen::Matrix3d::Identity()));
  const Tet4Coords x = distorted_tet4();
  const double six_volume =
      (x.col(1) - x.col(0)).cross(x.col(2) - x.col(0)).dot(x.col(3) - x.col(0));
  EXPECT_GT(six_volume, 0.0);
  EXPECT_NEAR(jacobian(x).determinant(), six_volume, 1e-12 * six_volume);
  // A straight tet10 has the tet4's constant Jacobian everywhere.
  for (const Eigen::Vector3d& xi : sample_points()) {
    EXPECT_TRUE(jacobian(straight_tet10(x), xi).isApprox(jacobian(x), 1e-12));
  }
  EXPECT_NEAR(min_jacobian_determinant(straight_tet10(x)), six_volume, 1e-12 * six_volume);
  EXPECT_GT(min_jacobian_determinant(curved_tet10()), 0.0);
}

TEST(Shape, InvertedElementThrowsNamingIt) {
  Tet4Coords x = distorted_tet4();
  x.col(1).swap(x.col(2));
  EXPECT_LT(min_jacobian_determinant(x), 0.0);
  try {
    tet4_gradients(x, 4711);
    FAIL() << "no exception for an inverted tet";
  } catch (const core::SolverError& e) {
    EXPECT_NE(std::string(e.what()).find("tet 4711"), std::string::npos) << e.what();
  }
  Tet10Coords y = curved_tet10();
  y.col(4) = y.col(2);  // the (0,1) mid-edge node dragged onto corner 2 folds the element
  EXPECT_LE(min_jacobian_determinant(y), 0.0);
  EXPECT_THROW(tet10_gradients(y, Eigen::Vector3d(0.5, 0.0, 0.0), 3), core::SolverError);
  // Degenerate (flat) tet.
  Tet4Coords flat = distorted_tet4();
  flat.col(3) = 0.5 * (flat.col(1) + flat.col(2));
  EXPECT_THROW(tet_barycentric(flat, Eigen::Vector3d::Zero(), 1), core::SolverError);
  // A pre-check with min_jacobian_determinant > 0 rejects exactly what the kernels reject.
  EXPECT_LE(min_jacobian_determinant(flat), 0.0);
  EXPECT_LE(min_jacobian_determinant(straight_tet10(flat)), 0.0);
  EXPECT_THROW(conductivity_matrix(straight_tet10(flat), 1.0, 1), core::SolverError);
}

TEST(Shape, PointLocationRoundTrip) {
  const Tet4Coords x = distorted_tet4();
  for (const Eigen::Vector3d& xi : sample_points()) {
    const Eigen::Vector4d l = tet_barycentric_of_natural(xi);
    const Eigen::Vector3d p = x * l;
    EXPECT_LT((tet_barycentric(x, p, 0) - l).norm(), 1e-12);
    EXPECT_LT((tet4_weights_at(x, p, 0) - l).norm(), 1e-12);
    EXPECT_GE(tet_barycentric(x, p, 0).minCoeff(), -1e-12);
  }
  // A point outside has a negative coordinate: beyond the face opposite corner 0.
  const Eigen::Vector3d outside = x * Eigen::Vector4d(-0.2, 0.5, 0.4, 0.3);
  EXPECT_NEAR(tet_barycentric(x, outside, 0)(0), -0.2, 1e-12);
}

TEST(Shape, Tet10WeightsSampleQuadraticFieldsAtArbitraryPoints) {
  const Tet10Coords x = straight_tet10(distorted_tet4() * 10.0);
  Eigen::Matrix<double, 10, 1> f;
  for (int a = 0; a < 10; ++a) f(a) = quadratic(x.col(a));
  const Eigen::Vector3d points[] = {x * tet10_shape(Eigen::Vector3d(0.2, 0.3, 0.1)), x.col(7),
                                    0.25 * x.leftCols<4>().rowwise().sum()};
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Matrix<double, 10, 1> w = tet10_weights_at(x, p, 0);
    EXPECT_NEAR(w.sum(), 1.0, 1e-13);
    EXPECT_NEAR(w.dot(f), quadratic(p), 1e-11);
    EXPECT_LT((x * w - p).norm(), 1e-12);
  }
}

TEST(Shape, FaceAreaAndNormal) {
  Tri3Coords t;
  t << 0.0, 0.03, 0.0,  //
      0.0, 0.0, 0.02,   //
      0.1, 0.1, 0.1;
  EXPECT_NEAR(face_area(t), 0.5 * 0.03 * 0.02, 1e-18);
  EXPECT_TRUE(face_normal(t, 0).isApprox(Eigen::Vector3d(0, 0, 1)));
  // Straight tri6: same area and normal; a curved one has a larger area.
  Tri6Coords s;
  s.leftCols<3>() = t;
  s.col(3) = 0.5 * (t.col(0) + t.col(1));
  s.col(4) = 0.5 * (t.col(1) + t.col(2));
  s.col(5) = 0.5 * (t.col(2) + t.col(0));
  EXPECT_NEAR(face_area(s), face_area(t), 1e-18);
  EXPECT_TRUE(face_normal(s, 0).isApprox(Eigen::Vector3d(0, 0, 1)));
  Tri6Coords bulged = s;
  bulged(2, 4) += 0.003;
  EXPECT_GT(face_area(bulged), face_area(s) * 1.001);
  Tri3Coords line = t;
  line.col(2) = 2.0 * t.col(1) - t.col(0);
  EXPECT_THROW(face_normal(line, 9), core::SolverError);
}

TEST(Shape, TetFacesPointOutward) {
  const Tet4Coords x = distorted_tet4();
  const Eigen::Vector3d centroid = 0.25 * x.rowwise().sum();
  const Tet10Coords y = straight_tet10(x);
  for (int k = 0; k < 4; ++k) {
    Tri3Coords f;
    Tri6Coords g;
    for (int i = 0; i < 3; ++i) f.col(i) = x.col(tet4_faces[k][i]);
    for (int i = 0; i < 6; ++i) g.col(i) = y.col(tet10_faces[k][i]);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NE(tet4_faces[k][i], k) << "face " << k << " must be opposite corner " << k;
      EXPECT_EQ(tet10_faces[k][i], tet4_faces[k][i]);
    }
    // Each tri6 mid-edge node is the midpoint of its face edge (0,1) (1,2) (2,0).
    for (int e = 0; e < 3; ++e) {
      EXPECT_LT((g.col(3 + e) - 0.5 * (g.col(e) + g.col((e + 1) % 3))).norm(), 1e-15);
    }
    const Eigen::Vector3d face_centroid = f.rowwise().sum() / 3.0;
    EXPECT_GT(face_normal(f, k).dot(face_centroid - centroid), 0.0) << "face " << k;
  }
}

}  // namespace
}  // namespace tt::solvers::kernels
