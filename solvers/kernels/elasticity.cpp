#include "solvers/kernels/elasticity.hpp"

#include <Eigen/LU>
#include <cmath>
#include <sstream>

#include "core/errors.hpp"
#include "solvers/kernels/quadrature.hpp"

namespace tt::solvers::kernels {

namespace {

/// Lame constants and the thermal stress modulus of an isotropic material.
struct Lame {
  double lambda = 0.0;  /// [Pa]
  double mu = 0.0;      /// shear modulus [Pa]
  double beta = 0.0;    /// 3 lambda + 2 mu = E / (1 - 2 nu) [Pa]
};

Lame lame_of(const ElasticMaterial& material) {
  const double e = material.youngs_modulus;
  const double nu = material.poisson_ratio;
  if (!(e > 0.0) || !(nu > -1.0 && nu < 0.5)) {
    std::ostringstream message;
    message << "elastic material: youngs_modulus = " << e << " Pa, poisson_ratio = " << nu
            << ": expected E > 0 and -1 < nu < 0.5; hint: E is in Pa (steel ~2.1e11)";
    throw core::SolverError(message.str());
  }
  Lame l;
  l.lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  l.mu = e / (2.0 * (1.0 + nu));
  l.beta = 3.0 * l.lambda + 2.0 * l.mu;
  return l;
}

/// Adds weight * g g^T to t, where g is the 3n vector of the gradients stacked node-major
/// (g_{3a+i} = dN_a/dx_i): the quadrature sum from which isotropic_stiffness builds K.
template <int Nodes>
void add_gradient_outer_product(Eigen::Matrix<double, 3 * Nodes, 3 * Nodes>& t,
                                const Eigen::Matrix<double, Nodes, 3>& dn_dx, double weight) {
  const Eigen::Matrix<double, 3, Nodes> g = dn_dx.transpose();
  const Eigen::Map<const Eigen::Matrix<double, 3 * Nodes, 1>> stacked(g.data());
  t.noalias() += weight * stacked * stacked.transpose();
}

/// B^T D B for an isotropic D without forming B: with T = integral g g^T,
/// K(3a+i, 3b+k) = lambda T(3a+i, 3b+k) + mu T(3a+k, 3b+i) + mu delta_ik sum_j T(3a+j, 3b+j).
template <int Nodes>
Eigen::Matrix<double, 3 * Nodes, 3 * Nodes> isotropic_stiffness(
    const Eigen::Matrix<double, 3 * Nodes, 3 * Nodes>& t, const Lame& l) {
  Eigen::Matrix<double, 3 * Nodes, 3 * Nodes> k;
  for (int b = 0; b < Nodes; ++b) {
    for (int a = 0; a < Nodes; ++a) {
      const Eigen::Matrix3d tab = t.template block<3, 3>(3 * a, 3 * b);
      Eigen::Matrix3d block = l.lambda * tab + l.mu * tab.transpose();
      block.diagonal().array() += l.mu * tab.trace();
      k.template block<3, 3>(3 * a, 3 * b) = block;
    }
  }
  return k;
}

template <int Nodes>
Eigen::Matrix<double, 6, 3 * Nodes> b_matrix(const Eigen::Matrix<double, Nodes, 3>& g) {
  Eigen::Matrix<double, 6, 3 * Nodes> b = Eigen::Matrix<double, 6, 3 * Nodes>::Zero();
  for (int a = 0; a < Nodes; ++a) {
    const int c = 3 * a;
    b(0, c) = g(a, 0);
    b(1, c + 1) = g(a, 1);
    b(2, c + 2) = g(a, 2);
    b(3, c + 1) = g(a, 2);  // gamma_yz
    b(3, c + 2) = g(a, 1);
    b(4, c) = g(a, 2);  // gamma_xz
    b(4, c + 2) = g(a, 0);
    b(5, c) = g(a, 1);  // gamma_xy
    b(5, c + 1) = g(a, 0);
  }
  return b;
}

/// sigma = lambda tr(eps) I + 2 mu eps - beta alpha dT I in Voigt order, from the gradients and
/// the node-major displacements.
template <int Nodes>
Vector6d isotropic_stress(const Eigen::Matrix<double, Nodes, 3>& g,
                          const Eigen::Matrix<double, 3 * Nodes, 1>& u, const Lame& l, double alpha,
                          double delta_t) {
  const Eigen::Map<const Eigen::Matrix<double, 3, Nodes>> nodal(u.data());
  const Eigen::Matrix3d h = nodal * g;  // displacement gradient du_i/dx_j
  const double volumetric = l.lambda * h.trace() - l.beta * alpha * delta_t;
  Vector6d s;
  s << 2.0 * l.mu * h(0, 0) + volumetric, 2.0 * l.mu * h(1, 1) + volumetric,
      2.0 * l.mu * h(2, 2) + volumetric, l.mu * (h(1, 2) + h(2, 1)), l.mu * (h(0, 2) + h(2, 0)),
      l.mu * (h(0, 1) + h(1, 0));
  return s;
}

}  // namespace

Matrix6d elasticity_matrix(const ElasticMaterial& material) {
  const Lame l = lame_of(material);
  Matrix6d d = Matrix6d::Zero();
  d.topLeftCorner<3, 3>().setConstant(l.lambda);
  d.diagonal() << l.lambda + 2.0 * l.mu, l.lambda + 2.0 * l.mu, l.lambda + 2.0 * l.mu, l.mu, l.mu,
      l.mu;
  return d;
}

Eigen::Matrix<double, 6, 12> strain_displacement_matrix(const Eigen::Matrix<double, 4, 3>& dn_dx) {
  return b_matrix<4>(dn_dx);
}

Eigen::Matrix<double, 6, 30> strain_displacement_matrix(const Eigen::Matrix<double, 10, 3>& dn_dx) {
  return b_matrix<10>(dn_dx);
}

Eigen::Matrix<double, 12, 12> stiffness_matrix(const Tet4Coords& x, const ElasticMaterial& material,
                                               int element) {
  const Lame l = lame_of(material);
  const ShapeGradients<4> g = tet4_gradients(x, element);
  Eigen::Matrix<double, 12, 12> t = Eigen::Matrix<double, 12, 12>::Zero();
  add_gradient_outer_product<4>(t, g.dn_dx, g.det_j / 6.0);
  return isotropic_stiffness<4>(t, l);
}

Eigen::Matrix<double, 30, 30> stiffness_matrix(const Tet10Coords& x,
                                               const ElasticMaterial& material, int element) {
  const Lame l = lame_of(material);
  // Degree 3, not the degree 2 a straight tet10 needs, so that K and the thermal load use the
  // same points: then free thermal expansion stays exactly stress-free on curved elements too.
  const TetRule<8>& rule = tet_rule_degree3();
  Eigen::Matrix<double, 30, 30> t = Eigen::Matrix<double, 30, 30>::Zero();
  for (int q = 0; q < 8; ++q) {
    const ShapeGradients<10> g = tet10_gradients(x, rule.points.col(q), element);
    add_gradient_outer_product<10>(t, g.dn_dx, rule.weights(q) * g.det_j);
  }
  return isotropic_stiffness<10>(t, l);
}

Tet4Vector thermal_load(const Tet4Coords& x, const ElasticMaterial& material,
                        const Eigen::Vector4d& temperatures, double reference_temperature,
                        int element) {
  const Lame l = lame_of(material);
  const ShapeGradients<4> g = tet4_gradients(x, element);
  // B constant and T linear: the integral of T is V times the mean nodal temperature.
  const double strain = material.thermal_expansion * (temperatures.mean() - reference_temperature);
  const Eigen::Matrix<double, 3, 4> f = (l.beta * strain * g.det_j / 6.0) * g.dn_dx.transpose();
  return Eigen::Map<const Tet4Vector>(f.data());
}

Tet10Vector thermal_load(const Tet10Coords& x, const ElasticMaterial& material,
                         const Eigen::Matrix<double, 10, 1>& temperatures,
                         double reference_temperature, int element) {
  const Lame l = lame_of(material);
  const TetRule<8>& rule = tet_rule_degree3();
  Eigen::Matrix<double, 3, 10> f = Eigen::Matrix<double, 3, 10>::Zero();
  for (int q = 0; q < 8; ++q) {
    const Eigen::Vector3d xi = rule.points.col(q);
    const ShapeGradients<10> g = tet10_gradients(x, xi, element);
    const double strain =
        material.thermal_expansion * (tet10_shape(xi).dot(temperatures) - reference_temperature);
    f += (rule.weights(q) * g.det_j * l.beta * strain) * g.dn_dx.transpose();
  }
  return Eigen::Map<const Tet10Vector>(f.data());
}

Eigen::Matrix<double, 12, 4> thermal_coupling_matrix(const Tet4Coords& x,
                                                     const ElasticMaterial& material, int element) {
  const Lame l = lame_of(material);
  const ShapeGradients<4> g = tet4_gradients(x, element);
  const Eigen::Matrix<double, 3, 4> gt = g.dn_dx.transpose();
  const Eigen::Map<const Tet4Vector> stacked(gt.data());
  // integral N_j dV = V / 4 for every node
  const double scale = l.beta * material.thermal_expansion * g.det_j / 24.0;
  return (scale * stacked).replicate<1, 4>();
}

Eigen::Matrix<double, 30, 10> thermal_coupling_matrix(const Tet10Coords& x,
                                                      const ElasticMaterial& material,
                                                      int element) {
  const Lame l = lame_of(material);
  const TetRule<8>& rule = tet_rule_degree3();
  Eigen::Matrix<double, 30, 10> c = Eigen::Matrix<double, 30, 10>::Zero();
  for (int q = 0; q < 8; ++q) {
    const Eigen::Vector3d xi = rule.points.col(q);
    const ShapeGradients<10> g = tet10_gradients(x, xi, element);
    const Eigen::Matrix<double, 3, 10> gt = g.dn_dx.transpose();
    const Eigen::Map<const Tet10Vector> stacked(gt.data());
    c.noalias() += (rule.weights(q) * g.det_j) * stacked * tet10_shape(xi).transpose();
  }
  return (l.beta * material.thermal_expansion) * c;
}

Vector6d stress_at(const Tet4Coords& x, const ElasticMaterial& material, const Tet4Vector& u,
                   const Eigen::Vector4d& temperatures, double reference_temperature,
                   const Eigen::Vector3d& xi, int element) {
  const Lame l = lame_of(material);
  const ShapeGradients<4> g = tet4_gradients(x, element);
  const double delta_t = tet4_shape(xi).dot(temperatures) - reference_temperature;
  return isotropic_stress<4>(g.dn_dx, u, l, material.thermal_expansion, delta_t);
}

Vector6d stress_at(const Tet10Coords& x, const ElasticMaterial& material, const Tet10Vector& u,
                   const Eigen::Matrix<double, 10, 1>& temperatures, double reference_temperature,
                   const Eigen::Vector3d& xi, int element) {
  const Lame l = lame_of(material);
  const ShapeGradients<10> g = tet10_gradients(x, xi, element);
  const double delta_t = tet10_shape(xi).dot(temperatures) - reference_temperature;
  return isotropic_stress<10>(g.dn_dx, u, l, material.thermal_expansion, delta_t);
}

Eigen::Matrix<double, 6, 4> nodal_stresses(const Tet4Coords& x, const ElasticMaterial& material,
                                           const Tet4Vector& u, const Eigen::Vector4d& temperatures,
                                           double reference_temperature, int element) {
  const Lame l = lame_of(material);
  const ShapeGradients<4> g = tet4_gradients(x, element);
  Eigen::Matrix<double, 6, 4> s;
  for (int a = 0; a < 4; ++a) {
    s.col(a) = isotropic_stress<4>(g.dn_dx, u, l, material.thermal_expansion,
                                   temperatures(a) - reference_temperature);
  }
  return s;
}

Eigen::Matrix<double, 6, 10> nodal_stresses(const Tet10Coords& x, const ElasticMaterial& material,
                                            const Tet10Vector& u,
                                            const Eigen::Matrix<double, 10, 1>& temperatures,
                                            double reference_temperature, int element) {
  const Lame l = lame_of(material);
  const Eigen::Matrix<double, 3, 10> nodes = tet10_node_natural();
  Eigen::Matrix<double, 6, 10> s;
  for (int a = 0; a < 10; ++a) {
    const ShapeGradients<10> g = tet10_gradients(x, nodes.col(a), element);
    s.col(a) = isotropic_stress<10>(g.dn_dx, u, l, material.thermal_expansion,
                                    temperatures(a) - reference_temperature);
  }
  return s;
}

double von_mises(const Vector6d& s) {
  const double normal =
      (s(0) - s(1)) * (s(0) - s(1)) + (s(1) - s(2)) * (s(1) - s(2)) + (s(2) - s(0)) * (s(2) - s(0));
  const double shear = s(3) * s(3) + s(4) * s(4) + s(5) * s(5);
  return std::sqrt(0.5 * normal + 3.0 * shear);
}

}  // namespace tt::solvers::kernels
