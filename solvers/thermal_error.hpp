// The thermal error at the tool: the TCP's displacement relative to t = 0 and the five-point
// probe quantities (ISO 230-3 style) on the spindle axis.
#pragma once

#include <Eigen/Core>
#include <array>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"

namespace tt::solvers {

/// Columns of ThermalError::values, in the order of thermal_error.csv after time_s.
enum ThermalErrorColumn {
  kDx,
  kDy,
  kDz,
  kDxZ1,
  kDyZ1,
  kDxZ2,
  kDyZ2,
  kTiltX,
  kTiltY,
  kThermalErrorColumns
};

struct ThermalError {
  Eigen::MatrixXd values;     /// #times x 9: displacements [m], tilts [rad]
  double probe_distance = 0;  /// D between the two probe points [m]
};

/// From node-major displacements (3 #nodes x #times [m]). Tilt about x is -(dy_z2 - dy_z1)/D
/// (right-handed rotation of the axis direction), tilt about y is (dx_z2 - dx_z1)/D.
ThermalError thermal_error(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                           const Eigen::MatrixXd& displacement);

/// The mesh nodes of the TCP and the two probe points (throws when the case does not name them).
std::array<int, 3> error_nodes(const mesh::TetMesh& mesh, const core::CaseSpec& spec);

/// The same from the displacements of only those three nodes: 9 x #times rows
/// (tcp x, y, z, z1 x, y, z, z2 x, y, z) [m].
ThermalError thermal_error_of(const Eigen::MatrixXd& node_displacements, double probe_distance);

}  // namespace tt::solvers
