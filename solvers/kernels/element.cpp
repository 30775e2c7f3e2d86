#include "solvers/kernels/element.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <limits>
#include <sstream>

#include "core/errors.hpp"
#include "solvers/kernels/internal.hpp"
#include "solvers/kernels/quadrature.hpp"

namespace tt::solvers::kernels {

namespace internal {

double checked_determinant(const Eigen::Matrix3d& j, int element, const Eigen::Vector3d& xi) {
  const double det_j = j.determinant();
  if (det_j > degenerate_ratio * j.col(0).norm() * j.col(1).norm() * j.col(2).norm()) return det_j;
  std::ostringstream message;
  message << "tet " << element << ": Jacobian determinant = " << det_j << " m^3 at natural point ("
          << xi.x() << ", " << xi.y() << ", " << xi.z()
          << "): must be > 0; hint: the element is inverted or degenerate, corners must satisfy "
             "(x1 - x0) x (x2 - x0) . (x3 - x0) > 0 (VTK order) and mid-edge nodes must lie near "
             "their edge midpoints";
  throw core::SolverError(message.str());
}

double checked_surface_jacobian(const Eigen::Matrix<double, 3, 2>& tangents, int face,
                                const Eigen::Vector2d& xi) {
  const double j = tangents.col(0).cross(tangents.col(1)).norm();
  if (j > degenerate_ratio * tangents.col(0).norm() * tangents.col(1).norm()) return j;
  std::ostringstream message;
  message << "face " << face << ": surface Jacobian = " << j << " m^2 at natural point (" << xi.x()
          << ", " << xi.y() << "): must be > 0; hint: the face has collinear or coincident nodes";
  throw core::SolverError(message.str());
}

}  // namespace internal

namespace {

/// 4 x 3 derivatives dL_i/dxi_j of the barycentric coordinates.
Eigen::Matrix<double, 4, 3> barycentric_derivatives() {
  Eigen::Matrix<double, 4, 3> d;
  d << -1, -1, -1,  //
      1, 0, 0,      //
      0, 1, 0,      //
      0, 0, 1;
  return d;
}

/// det J, or min(det J, 0) where checked_determinant would reject it as flat to rounding.
double acceptance_determinant(const Eigen::Matrix3d& j) {
  const double det_j = j.determinant();
  const double bound =
      internal::degenerate_ratio * j.col(0).norm() * j.col(1).norm() * j.col(2).norm();
  return det_j > bound ? det_j : std::min(det_j, 0.0);
}

template <int Points>
double min_det_over(const Tet10Coords& x, const Eigen::Matrix<double, 3, Points>& points) {
  double smallest = std::numeric_limits<double>::infinity();
  for (int q = 0; q < Points; ++q) {
    smallest = std::min(smallest, acceptance_determinant(jacobian(x, points.col(q))));
  }
  return smallest;
}

}  // namespace

Eigen::Vector4d tet_barycentric_of_natural(const Eigen::Vector3d& xi) {
  return {1.0 - xi.x() - xi.y() - xi.z(), xi.x(), xi.y(), xi.z()};
}

Eigen::Vector4d tet4_shape(const Eigen::Vector3d& xi) {
  return tet_barycentric_of_natural(xi);
}

Eigen::Matrix<double, 4, 3> tet4_shape_derivatives() {
  return barycentric_derivatives();
}

Eigen::Matrix<double, 10, 1> tet10_shape(const Eigen::Vector3d& xi) {
  const Eigen::Vector4d l = tet_barycentric_of_natural(xi);
  Eigen::Matrix<double, 10, 1> n;
  for (int i = 0; i < 4; ++i) n(i) = l(i) * (2.0 * l(i) - 1.0);
  for (int e = 0; e < 6; ++e) n(4 + e) = 4.0 * l(tet_edges[e][0]) * l(tet_edges[e][1]);
  return n;
}

Eigen::Matrix<double, 10, 3> tet10_shape_derivatives(const Eigen::Vector3d& xi) {
  const Eigen::Vector4d l = tet_barycentric_of_natural(xi);
  const Eigen::Matrix<double, 4, 3> dl = barycentric_derivatives();
  Eigen::Matrix<double, 10, 3> d;
  for (int i = 0; i < 4; ++i) d.row(i) = (4.0 * l(i) - 1.0) * dl.row(i);
  for (int e = 0; e < 6; ++e) {
    const int a = tet_edges[e][0];
    const int b = tet_edges[e][1];
    d.row(4 + e) = 4.0 * (l(b) * dl.row(a) + l(a) * dl.row(b));
  }
  return d;
}

Eigen::Matrix<double, 3, 10> tet10_node_natural() {
  Eigen::Matrix<double, 3, 10> xi;
  xi.leftCols<4>() << 0, 1, 0, 0,  //
      0, 0, 1, 0,                  //
      0, 0, 0, 1;
  for (int e = 0; e < 6; ++e) {
    xi.col(4 + e) = 0.5 * (xi.col(tet_edges[e][0]) + xi.col(tet_edges[e][1]));
  }
  return xi;
}

Eigen::Vector3d tri3_shape(const Eigen::Vector2d& xi) {
  return {1.0 - xi.x() - xi.y(), xi.x(), xi.y()};
}

Eigen::Matrix<double, 3, 2> tri3_shape_derivatives() {
  Eigen::Matrix<double, 3, 2> d;
  d << -1, -1,  //
      1, 0,     //
      0, 1;
  return d;
}

Eigen::Matrix<double, 6, 1> tri6_shape(const Eigen::Vector2d& xi) {
  const Eigen::Vector3d l = tri3_shape(xi);
  Eigen::Matrix<double, 6, 1> n;
  for (int i = 0; i < 3; ++i) n(i) = l(i) * (2.0 * l(i) - 1.0);
  for (int e = 0; e < 3; ++e) n(3 + e) = 4.0 * l(e) * l((e + 1) % 3);
  return n;
}

Eigen::Matrix<double, 6, 2> tri6_shape_derivatives(const Eigen::Vector2d& xi) {
  const Eigen::Vector3d l = tri3_shape(xi);
  const Eigen::Matrix<double, 3, 2> dl = tri3_shape_derivatives();
  Eigen::Matrix<double, 6, 2> d;
  for (int i = 0; i < 3; ++i) d.row(i) = (4.0 * l(i) - 1.0) * dl.row(i);
  for (int e = 0; e < 3; ++e) {
    const int b = (e + 1) % 3;
    d.row(3 + e) = 4.0 * (l(b) * dl.row(e) + l(e) * dl.row(b));
  }
  return d;
}

Eigen::Matrix3d jacobian(const Tet4Coords& x) {
  return x * barycentric_derivatives();
}

Eigen::Matrix3d jacobian(const Tet10Coords& x, const Eigen::Vector3d& xi) {
  return x * tet10_shape_derivatives(xi);
}

double min_jacobian_determinant(const Tet4Coords& x) {
  return acceptance_determinant(jacobian(x));
}

double min_jacobian_determinant(const Tet10Coords& x) {
  return std::min({min_det_over<10>(x, tet10_node_natural()),
                   min_det_over<4>(x, tet_rule_degree2().points),
                   min_det_over<8>(x, tet_rule_degree3().points),
                   min_det_over<14>(x, tet_rule_degree5().points)});
}

ShapeGradients<4> tet4_gradients(const Tet4Coords& x, int element) {
  const Eigen::Matrix<double, 4, 3> dn_dxi = barycentric_derivatives();
  const Eigen::Matrix3d j = x * dn_dxi;
  ShapeGradients<4> g;
  g.det_j = internal::checked_determinant(j, element, Eigen::Vector3d::Zero());
  g.dn_dx = dn_dxi * j.inverse();
  return g;
}

ShapeGradients<10> tet10_gradients(const Tet10Coords& x, const Eigen::Vector3d& xi, int element) {
  const Eigen::Matrix<double, 10, 3> dn_dxi = tet10_shape_derivatives(xi);
  const Eigen::Matrix3d j = x * dn_dxi;
  ShapeGradients<10> g;
  g.det_j = internal::checked_determinant(j, element, xi);
  g.dn_dx = dn_dxi * j.inverse();
  return g;
}

Eigen::Vector4d tet_barycentric(const Tet4Coords& x, const Eigen::Vector3d& p, int element) {
  const Eigen::Matrix3d j = jacobian(x);
  internal::checked_determinant(j, element, Eigen::Vector3d::Zero());
  return tet_barycentric_of_natural(j.inverse() * (p - x.col(0)));
}

Eigen::Vector4d tet_barycentric(const Tet10Coords& x, const Eigen::Vector3d& p, int element) {
  return tet_barycentric(Tet4Coords(x.leftCols<4>()), p, element);
}

Eigen::Vector4d tet4_weights_at(const Tet4Coords& x, const Eigen::Vector3d& p, int element) {
  return tet_barycentric(x, p, element);
}

Eigen::Matrix<double, 10, 1> tet10_weights_at(const Tet10Coords& x, const Eigen::Vector3d& p,
                                              int element) {
  return tet10_shape(tet_barycentric(x, p, element).tail<3>());
}

double face_area(const Tri3Coords& x) {
  return 0.5 * (x.col(1) - x.col(0)).cross(x.col(2) - x.col(0)).norm();
}

double face_area(const Tri6Coords& x) {
  const TriRule<6>& rule = tri_rule_degree4();
  double area = 0.0;
  for (int q = 0; q < 6; ++q) {
    const Eigen::Matrix<double, 3, 2> tangents = x * tri6_shape_derivatives(rule.points.col(q));
    area += rule.weights(q) * tangents.col(0).cross(tangents.col(1)).norm();
  }
  return area;
}

Eigen::Vector3d face_normal(const Tri3Coords& x, int face) {
  const Eigen::Matrix<double, 3, 2> tangents = x * tri3_shape_derivatives();
  const double norm = internal::checked_surface_jacobian(tangents, face, Eigen::Vector2d::Zero());
  return tangents.col(0).cross(tangents.col(1)) / norm;
}

Eigen::Vector3d face_normal(const Tri6Coords& x, int face) {
  return face_normal(Tri3Coords(x.leftCols<3>()), face);
}

}  // namespace tt::solvers::kernels
