// The thermal error at the tool: the TCP's displacement relative to t = 0 and the five-point
// probe quantities (ISO 230-3 style) on the spindle axis.
#pragma once

#include <Eigen/Core>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"

namespace tt::solvers {

/// Columns of ThermalError::values, in the order of thermal_error.csv after time_s.
enum ThermalErrorColumn { kDx, kDy, kDz, kDxZ1, kDyZ1, kDxZ2, kDyZ2, kTiltX, kTiltY, kThermalErrorColumns };

struct ThermalError {
  Eigen::MatrixXd values;  /// #times x 9: displacements [m], tilts [rad]
  double probe_distance = 0;  /// D between the two probe points [m]
};

/// From node-major displacements (3 #nodes x #times [m]). Tilt about x is -(dy_z2 - dy_z1)/D
/// (right-handed rotation of the axis direction), tilt about y is (dx_z2 - dx_z1)/D.
ThermalError thermal_error(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                           const Eigen::MatrixXd& displacement);

}  // namespace tt::solvers
