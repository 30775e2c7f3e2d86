// Heat conduction kernels: element matrices and load vectors of
//   rho c dT/dt - div(k grad T) = q   in the body,
//   -k grad T . n = h (T - T_sink)    on convective faces,
//   -k grad T . n = -q_in             on faces with a prescribed heat flux into the body,
// plus element integrals used to verify energy balances independently of the matrices.
// Material values are per element (the assembler looks them up by region). Temperatures may be
// in K or in degC as long as all temperatures of one call share the unit (only differences
// matter). See element.hpp for node order, natural coordinates and the `element` argument.
#pragma once

#include <Eigen/Core>

#include "solvers/kernels/element.hpp"

namespace tt::solvers::kernels {

// ---- Volume kernels --------------------------------------------------------------------------

/// k * integral grad N grad N^T dV, 4 x 4 [W/K]; `conductivity` k [W/(m K)].
Eigen::Matrix4d conductivity_matrix(const Tet4Coords& x, double conductivity, int element);
/// Same for the tet10, 10 x 10 [W/K] (4-point rule: exact for straight edges).
Eigen::Matrix<double, 10, 10> conductivity_matrix(const Tet10Coords& x, double conductivity,
                                                  int element);

/// Consistent capacity rho c * integral N N^T dV, 4 x 4 [J/K]; `heat_capacity` rho c
/// [J/(m^3 K)].
Eigen::Matrix4d capacity_matrix(const Tet4Coords& x, double heat_capacity, int element);
/// Same for the tet10, 10 x 10 [J/K] (14-point degree-5 rule: exact for straight edges).
Eigen::Matrix<double, 10, 10> capacity_matrix(const Tet10Coords& x, double heat_capacity,
                                              int element);

/// Diagonal of the lumped capacity [J/K], summing to rho c V. tet4: row sums (rho c V / 4 each).
Eigen::Vector4d lumped_capacity(const Tet4Coords& x, double heat_capacity, int element);
/// tet10: HRZ lumping, the diagonal of the consistent matrix scaled to sum to rho c V (corners
/// rho c V / 36, mid-edge nodes 4 rho c V / 27 on a straight tet). Row sums would give the
/// corners a negative mass (-rho c V / 20).
Eigen::Matrix<double, 10, 1> lumped_capacity(const Tet10Coords& x, double heat_capacity,
                                             int element);

/// q * integral N dV [W]; `heat_source` q [W/m^3].
Eigen::Vector4d source_vector(const Tet4Coords& x, double heat_source, int element);
Eigen::Matrix<double, 10, 1> source_vector(const Tet10Coords& x, double heat_source, int element);

/// Heat flux -k grad T [W/m^2] for nodal temperatures T: constant on the tet4, at natural point
/// xi on the tet10.
Eigen::Vector3d heat_flux_at(const Tet4Coords& x, double conductivity,
                             const Eigen::Vector4d& temperatures, int element);
Eigen::Vector3d heat_flux_at(const Tet10Coords& x, double conductivity,
                             const Eigen::Matrix<double, 10, 1>& temperatures,
                             const Eigen::Vector3d& xi, int element);

// ---- Face kernels (`face` is the face's index, used in error messages only) -------------------

/// h * integral N N^T dA [W/K]; `film_coefficient` h [W/(m^2 K)].
Eigen::Matrix3d convection_matrix(const Tri3Coords& x, double film_coefficient, int face);
Eigen::Matrix<double, 6, 6> convection_matrix(const Tri6Coords& x, double film_coefficient,
                                              int face);

/// h T_sink * integral N dA [W], the right-hand side that goes with convection_matrix.
Eigen::Vector3d convection_load(const Tri3Coords& x, double film_coefficient,
                                double sink_temperature, int face);
Eigen::Matrix<double, 6, 1> convection_load(const Tri6Coords& x, double film_coefficient,
                                            double sink_temperature, int face);

/// q_in * integral N dA [W]; `heat_flux_in` q_in [W/m^2], positive into the body.
Eigen::Vector3d flux_load(const Tri3Coords& x, double heat_flux_in, int face);
Eigen::Matrix<double, 6, 1> flux_load(const Tri6Coords& x, double heat_flux_in, int face);

// ---- Integrals for verification (by quadrature, independent of the matrices above) -----------

/// Element volume [m^3].
double element_volume(const Tet4Coords& x, int element);
double element_volume(const Tet10Coords& x, int element);

/// Heat stored relative to a uniform T0: integral rho c (T - T0) dV [J].
double stored_heat(const Tet4Coords& x, double heat_capacity, const Eigen::Vector4d& temperatures,
                   double initial_temperature, int element);
double stored_heat(const Tet10Coords& x, double heat_capacity,
                   const Eigen::Matrix<double, 10, 1>& temperatures, double initial_temperature,
                   int element);

/// Heat rate leaving through a convective face: integral h (T - T_sink) dA [W].
double convected_heat_rate(const Tri3Coords& x, double film_coefficient,
                           const Eigen::Vector3d& temperatures, double sink_temperature, int face);
double convected_heat_rate(const Tri6Coords& x, double film_coefficient,
                           const Eigen::Matrix<double, 6, 1>& temperatures, double sink_temperature,
                           int face);

}  // namespace tt::solvers::kernels
