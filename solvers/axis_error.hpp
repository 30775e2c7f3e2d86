// Thermal error along a feed axis (seed 004): the drift of n measurement points along the axis,
// and at each time a polynomial in axis position fitted to it per direction, whose coefficients a
// CNC takes to compensate at any target position.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"

namespace tt::solvers {

struct AxisError {
  std::vector<std::string> points;  /// ids of the measurement points, as in the case
  Eigen::VectorXd positions;        /// #points coordinate along the feed axis [m]
  Eigen::MatrixXd values;  /// #times x 3 #points: (dx, dy, dz) of each point minus t = 0 [m]
};

/// From node-major displacements (3 #nodes x #times [m]). Throws SolverError when an axis point
/// is not a named point of the mesh.
AxisError axis_error(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                     const Eigen::MatrixXd& displacement);

/// From the axis points' own displacements: #times x 3 #points, (dx, dy, dz) of each point in the
/// case's axis_points order relative to any fixed state [m] (e.g. read through adjoint influence
/// rows). Positions are the points' coordinates along the feed axis (a named point is a mesh
/// vertex at exactly its position). Throws SolverError when an axis point is not a named point of
/// the case or the columns do not match the points.
AxisError axis_error_at_points(const core::CaseSpec& spec,
                               const Eigen::MatrixXd& point_displacement);

struct AxisPolynomial {
  int degree = 0;
  /// Per direction (x, y, z): #times x (degree + 1) coefficients c_k of e(p) = sum_k c_k p^k,
  /// p the axis position [m], c_k [m / m^k].
  std::array<Eigen::MatrixXd, 3> coefficients;
  std::array<Eigen::VectorXd, 3> rms;  /// per direction: #times RMS of the points' residuals [m]
  std::array<Eigen::VectorXd, 3> max;  /// per direction: #times largest |residual| [m]
};

/// Least squares per time and direction (QR of the Vandermonde matrix). Throws SolverError when
/// there are fewer than degree + 1 points or two points share a position.
AxisPolynomial axis_polynomial(const AxisError& error, int degree);

/// The polynomial's value at positions p (#p [m]) for one time and direction [m].
Eigen::VectorXd axis_polynomial_value(const AxisPolynomial& poly, int direction, Eigen::Index time,
                                      const Eigen::VectorXd& positions);

/// What is left at the axis points when a CNC compensates with `poly` (fitted to any estimate of
/// the error, e.g. a model's predictions): #times x 3 #points, `measured` minus the polynomial at
/// each point's position, columns as in AxisError::values [m]. Throws SolverError when the two
/// differ in times or points.
Eigen::MatrixXd axis_polynomial_residual(const AxisPolynomial& poly, const AxisError& measured);

}  // namespace tt::solvers
