// Helpers shared by the kernel sources; not part of the public interface.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tt::solvers::kernels::internal {

/// An element is rejected when det J <= degenerate_ratio x the product of J's column norms (the
/// largest det J those columns allow), i.e. when it is inverted or flat to rounding. The ratio
/// is about 0.7 for a regular tet and rarely below 1e-4 for a usable sliver.
inline constexpr double degenerate_ratio = 1e-12;

/// det J [m^3]; throws SolverError naming `element` and xi if it is not acceptable.
double checked_determinant(const Eigen::Matrix3d& j, int element, const Eigen::Vector3d& xi);

/// |dx/dr x dx/ds| [m^2] from the 3 x 2 tangents (= 2 x area for a straight triangle); throws
/// SolverError naming `face` and xi if the face is degenerate there.
double checked_surface_jacobian(const Eigen::Matrix<double, 3, 2>& tangents, int face,
                                const Eigen::Vector2d& xi);

}  // namespace tt::solvers::kernels::internal
