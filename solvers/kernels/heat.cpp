#include "solvers/kernels/heat.hpp"

#include <Eigen/LU>

#include "solvers/kernels/internal.hpp"
#include "solvers/kernels/quadrature.hpp"

namespace tt::solvers::kernels {

namespace {

/// Surface Jacobian of a straight triangle (2 x area) [m^2], checked.
double checked_tri3_jacobian(const Tri3Coords& x, int face) {
  return internal::checked_surface_jacobian(x * tri3_shape_derivatives(), face,
                                            Eigen::Vector2d::Constant(1.0 / 3.0));
}

/// Surface Jacobian of a quadratic triangle at xi [m^2], checked.
double checked_tri6_jacobian(const Tri6Coords& x, const Eigen::Vector2d& xi, int face) {
  return internal::checked_surface_jacobian(x * tri6_shape_derivatives(xi), face, xi);
}

/// det J of the tet10 at xi, checked.
double checked_tet10_det(const Tet10Coords& x, const Eigen::Vector3d& xi, int element) {
  return internal::checked_determinant(jacobian(x, xi), element, xi);
}

}  // namespace

// ---- Volume kernels --------------------------------------------------------------------------

Eigen::Matrix4d conductivity_matrix(const Tet4Coords& x, double conductivity, int element) {
  const ShapeGradients<4> g = tet4_gradients(x, element);
  return (conductivity * g.det_j / 6.0) * g.dn_dx.lazyProduct(g.dn_dx.transpose());
}

Eigen::Matrix<double, 10, 10> conductivity_matrix(const Tet10Coords& x, double conductivity,
                                                  int element) {
  const TetRule<4>& rule = tet_rule_degree2();
  Eigen::Matrix<double, 10, 10> k = Eigen::Matrix<double, 10, 10>::Zero();
  for (int q = 0; q < 4; ++q) {
    const ShapeGradients<10> g = tet10_gradients(x, rule.points.col(q), element);
    // lazyProduct: coefficient-based, not Eigen's blocked (and OpenMP-aware) GEMM
    k.noalias() += (rule.weights(q) * g.det_j) * g.dn_dx.lazyProduct(g.dn_dx.transpose());
  }
  return conductivity * k;
}

Eigen::Matrix4d capacity_matrix(const Tet4Coords& x, double heat_capacity, int element) {
  const double mass = heat_capacity * element_volume(x, element);
  // integral L_i L_j dV = V (1 + delta_ij) / 20
  return (mass / 20.0) * (Eigen::Matrix4d::Ones() + Eigen::Matrix4d::Identity());
}

Eigen::Matrix<double, 10, 10> capacity_matrix(const Tet10Coords& x, double heat_capacity,
                                              int element) {
  const TetRule<14>& rule = tet_rule_degree5();
  Eigen::Matrix<double, 10, 10> m = Eigen::Matrix<double, 10, 10>::Zero();
  for (int q = 0; q < 14; ++q) {
    const Eigen::Vector3d xi = rule.points.col(q);
    const Eigen::Matrix<double, 10, 1> n = tet10_shape(xi);
    m.noalias() += (rule.weights(q) * checked_tet10_det(x, xi, element)) * n * n.transpose();
  }
  return heat_capacity * m;
}

Eigen::Vector4d lumped_capacity(const Tet4Coords& x, double heat_capacity, int element) {
  return Eigen::Vector4d::Constant(heat_capacity * element_volume(x, element) / 4.0);
}

Eigen::Matrix<double, 10, 1> lumped_capacity(const Tet10Coords& x, double heat_capacity,
                                             int element) {
  // HRZ: the diagonal of the consistent matrix, scaled so that the total is rho c V.
  const TetRule<14>& rule = tet_rule_degree5();
  Eigen::Matrix<double, 10, 1> diagonal = Eigen::Matrix<double, 10, 1>::Zero();
  double volume = 0.0;
  for (int q = 0; q < 14; ++q) {
    const Eigen::Vector3d xi = rule.points.col(q);
    const double dv = rule.weights(q) * checked_tet10_det(x, xi, element);
    diagonal += dv * tet10_shape(xi).cwiseAbs2();
    volume += dv;
  }
  return diagonal * (heat_capacity * volume / diagonal.sum());
}

Eigen::Vector4d source_vector(const Tet4Coords& x, double heat_source, int element) {
  return Eigen::Vector4d::Constant(heat_source * element_volume(x, element) / 4.0);
}

Eigen::Matrix<double, 10, 1> source_vector(const Tet10Coords& x, double heat_source, int element) {
  const TetRule<4>& rule = tet_rule_degree2();
  Eigen::Matrix<double, 10, 1> f = Eigen::Matrix<double, 10, 1>::Zero();
  for (int q = 0; q < 4; ++q) {
    const Eigen::Vector3d xi = rule.points.col(q);
    f += (rule.weights(q) * checked_tet10_det(x, xi, element)) * tet10_shape(xi);
  }
  return heat_source * f;
}

Eigen::Vector3d heat_flux_at(const Tet4Coords& x, double conductivity,
                             const Eigen::Vector4d& temperatures, int element) {
  return -conductivity * tet4_gradients(x, element).dn_dx.transpose() * temperatures;
}

Eigen::Vector3d heat_flux_at(const Tet10Coords& x, double conductivity,
                             const Eigen::Matrix<double, 10, 1>& temperatures,
                             const Eigen::Vector3d& xi, int element) {
  return -conductivity * tet10_gradients(x, xi, element).dn_dx.transpose() * temperatures;
}

// ---- Face kernels ----------------------------------------------------------------------------

Eigen::Matrix3d convection_matrix(const Tri3Coords& x, double film_coefficient, int face) {
  const double area = 0.5 * checked_tri3_jacobian(x, face);
  // integral L_i L_j dA = A (1 + delta_ij) / 12
  return (film_coefficient * area / 12.0) * (Eigen::Matrix3d::Ones() + Eigen::Matrix3d::Identity());
}

Eigen::Matrix<double, 6, 6> convection_matrix(const Tri6Coords& x, double film_coefficient,
                                              int face) {
  const TriRule<6>& rule = tri_rule_degree4();
  Eigen::Matrix<double, 6, 6> m = Eigen::Matrix<double, 6, 6>::Zero();
  for (int q = 0; q < 6; ++q) {
    const Eigen::Vector2d xi = rule.points.col(q);
    const Eigen::Matrix<double, 6, 1> n = tri6_shape(xi);
    m.noalias() += (rule.weights(q) * checked_tri6_jacobian(x, xi, face)) * n * n.transpose();
  }
  return film_coefficient * m;
}

Eigen::Vector3d flux_load(const Tri3Coords& x, double heat_flux_in, int face) {
  return Eigen::Vector3d::Constant(heat_flux_in * checked_tri3_jacobian(x, face) / 6.0);
}

Eigen::Matrix<double, 6, 1> flux_load(const Tri6Coords& x, double heat_flux_in, int face) {
  const TriRule<6>& rule = tri_rule_degree4();
  Eigen::Matrix<double, 6, 1> f = Eigen::Matrix<double, 6, 1>::Zero();
  for (int q = 0; q < 6; ++q) {
    const Eigen::Vector2d xi = rule.points.col(q);
    f += (rule.weights(q) * checked_tri6_jacobian(x, xi, face)) * tri6_shape(xi);
  }
  return heat_flux_in * f;
}

Eigen::Vector3d convection_load(const Tri3Coords& x, double film_coefficient,
                                double sink_temperature, int face) {
  return flux_load(x, film_coefficient * sink_temperature, face);
}

Eigen::Matrix<double, 6, 1> convection_load(const Tri6Coords& x, double film_coefficient,
                                            double sink_temperature, int face) {
  return flux_load(x, film_coefficient * sink_temperature, face);
}

// ---- Integrals for verification --------------------------------------------------------------

double element_volume(const Tet4Coords& x, int element) {
  return internal::checked_determinant(jacobian(x), element, Eigen::Vector3d::Zero()) / 6.0;
}

double element_volume(const Tet10Coords& x, int element) {
  // det J is a cubic in xi (J is linear), so the degree-3 rule is exact even for curved edges.
  const TetRule<8>& rule = tet_rule_degree3();
  double volume = 0.0;
  for (int q = 0; q < 8; ++q) {
    volume += rule.weights(q) * checked_tet10_det(x, rule.points.col(q), element);
  }
  return volume;
}

double stored_heat(const Tet4Coords& x, double heat_capacity, const Eigen::Vector4d& temperatures,
                   double initial_temperature, int element) {
  const TetRule<1>& rule = tet_rule_degree1();
  const double t = tet4_shape(rule.points.col(0)).dot(temperatures);
  return heat_capacity * element_volume(x, element) * (t - initial_temperature);
}

double stored_heat(const Tet10Coords& x, double heat_capacity,
                   const Eigen::Matrix<double, 10, 1>& temperatures, double initial_temperature,
                   int element) {
  // quadratic T times cubic det J: degree 5
  const TetRule<14>& rule = tet_rule_degree5();
  double heat = 0.0;
  for (int q = 0; q < 14; ++q) {
    const Eigen::Vector3d xi = rule.points.col(q);
    heat += rule.weights(q) * checked_tet10_det(x, xi, element) *
            (tet10_shape(xi).dot(temperatures) - initial_temperature);
  }
  return heat_capacity * heat;
}

double convected_heat_rate(const Tri3Coords& x, double film_coefficient,
                           const Eigen::Vector3d& temperatures, double sink_temperature, int face) {
  const TriRule<3>& rule = tri_rule_degree2();
  const double j = checked_tri3_jacobian(x, face);
  double rate = 0.0;
  for (int q = 0; q < 3; ++q) {
    rate +=
        rule.weights(q) * j * (tri3_shape(rule.points.col(q)).dot(temperatures) - sink_temperature);
  }
  return film_coefficient * rate;
}

double convected_heat_rate(const Tri6Coords& x, double film_coefficient,
                           const Eigen::Matrix<double, 6, 1>& temperatures, double sink_temperature,
                           int face) {
  const TriRule<6>& rule = tri_rule_degree4();
  double rate = 0.0;
  for (int q = 0; q < 6; ++q) {
    const Eigen::Vector2d xi = rule.points.col(q);
    rate += rule.weights(q) * checked_tri6_jacobian(x, xi, face) *
            (tri6_shape(xi).dot(temperatures) - sink_temperature);
  }
  return film_coefficient * rate;
}

}  // namespace tt::solvers::kernels
