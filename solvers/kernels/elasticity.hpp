// Linear thermo-elasticity kernels for an isotropic material:
//   sigma = D (epsilon - alpha (T - T_ref) m),   m = (1, 1, 1, 0, 0, 0).
// Voigt order of stresses and strains: xx, yy, zz, yz, xz, xy, with engineering shear strains
// (gamma_yz = 2 epsilon_yz). Element dofs are node-major: (u_x, u_y, u_z) of node 0, then node 1,
// ... (3n entries). Temperatures may be in K or degC if T and T_ref share the unit. See
// element.hpp for node order, natural coordinates and the `element` argument.
#pragma once

#include <Eigen/Core>

#include "solvers/kernels/element.hpp"

namespace tt::solvers::kernels {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Tet4Vector = Eigen::Matrix<double, 12, 1>;   /// tet4 dofs, node-major x, y, z
using Tet10Vector = Eigen::Matrix<double, 30, 1>;  /// tet10 dofs, node-major x, y, z

struct ElasticMaterial {
  double youngs_modulus = 0.0;     /// E [Pa]
  double poisson_ratio = 0.0;      /// nu [-], in (-1, 0.5)
  double thermal_expansion = 0.0;  /// alpha [1/K]
};

/// 6 x 6 isotropic elasticity matrix D [Pa]. Throws SolverError unless E > 0 and -1 < nu < 0.5.
Matrix6d elasticity_matrix(const ElasticMaterial& material);

/// 6 x 3n strain-displacement matrix B [1/m] from #nodes x 3 physical gradients (see
/// tet4_gradients, tet10_gradients): epsilon = B u.
Eigen::Matrix<double, 6, 12> strain_displacement_matrix(const Eigen::Matrix<double, 4, 3>& dn_dx);
Eigen::Matrix<double, 6, 30> strain_displacement_matrix(const Eigen::Matrix<double, 10, 3>& dn_dx);

/// integral B^T D B dV, 12 x 12 [N/m].
Eigen::Matrix<double, 12, 12> stiffness_matrix(const Tet4Coords& x, const ElasticMaterial& material,
                                               int element);
/// Same for the tet10, 30 x 30 [N/m], with the 8-point degree-3 rule of thermal_load (exact for
/// straight edges, and free thermal expansion stays exactly stress-free on curved ones).
Eigen::Matrix<double, 30, 30> stiffness_matrix(const Tet10Coords& x,
                                               const ElasticMaterial& material, int element);

/// integral B^T D alpha (T - T_ref) m dV [N] with T interpolated from the nodal temperatures.
Tet4Vector thermal_load(const Tet4Coords& x, const ElasticMaterial& material,
                        const Eigen::Vector4d& temperatures, double reference_temperature,
                        int element);
/// tet10: quadratic T times linear B is cubic, integrated by the 8-point degree-3 rule.
Tet10Vector thermal_load(const Tet10Coords& x, const ElasticMaterial& material,
                         const Eigen::Matrix<double, 10, 1>& temperatures,
                         double reference_temperature, int element);

/// Thermal coupling G, 3n x n [N/K]: thermal_load = G (T - T_ref), column j = integral
/// beta alpha N_j grad N dV (beta = E / (1 - 2 nu)), by the same rules as thermal_load. For an
/// assembler that stores the global G once instead of calling thermal_load per time step.
Eigen::Matrix<double, 12, 4> thermal_coupling_matrix(const Tet4Coords& x,
                                                     const ElasticMaterial& material, int element);
Eigen::Matrix<double, 30, 10> thermal_coupling_matrix(const Tet10Coords& x,
                                                      const ElasticMaterial& material, int element);

/// Stress sigma = D (B u - alpha (T - T_ref) m) [Pa] at natural point xi.
Vector6d stress_at(const Tet4Coords& x, const ElasticMaterial& material, const Tet4Vector& u,
                   const Eigen::Vector4d& temperatures, double reference_temperature,
                   const Eigen::Vector3d& xi, int element);
Vector6d stress_at(const Tet10Coords& x, const ElasticMaterial& material, const Tet10Vector& u,
                   const Eigen::Matrix<double, 10, 1>& temperatures, double reference_temperature,
                   const Eigen::Vector3d& xi, int element);

/// 6 x #nodes stress at each node of the element [Pa], evaluated from the element's own fields
/// at the node (for the tet10 this equals extrapolation from the 4 Gauss points when the
/// temperature is linear). A smoothed nodal field averages these over the elements at a node.
Eigen::Matrix<double, 6, 4> nodal_stresses(const Tet4Coords& x, const ElasticMaterial& material,
                                           const Tet4Vector& u, const Eigen::Vector4d& temperatures,
                                           double reference_temperature, int element);
Eigen::Matrix<double, 6, 10> nodal_stresses(const Tet10Coords& x, const ElasticMaterial& material,
                                            const Tet10Vector& u,
                                            const Eigen::Matrix<double, 10, 1>& temperatures,
                                            double reference_temperature, int element);

/// Von Mises equivalent stress [Pa] of a Voigt stress.
double von_mises(const Vector6d& stress);

}  // namespace tt::solvers::kernels
