// Reference and distorted elements shared by the kernel tests.
#pragma once

#include <Eigen/Core>

#include "solvers/kernels/element.hpp"

namespace tt::solvers::kernels::testing {

/// The reference tet: node 0 at the origin, nodes 1, 2, 3 on the x, y, z axes [m].
inline Tet4Coords reference_tet4() {
  Tet4Coords x;
  x << 0, 1, 0, 0,  //
      0, 0, 1, 0,   //
      0, 0, 0, 1;
  return x;
}

/// A skewed tet of a few cm, positively oriented, far from the origin [m].
inline Tet4Coords distorted_tet4() {
  Tet4Coords x;
  x << 0.101, 0.131, 0.108, 0.104,  //
      0.205, 0.207, 0.229, 0.213,   //
      -0.020, -0.018, -0.019, 0.004;
  return x;
}

/// The tet10 with straight edges on the corners of x.
inline Tet10Coords straight_tet10(const Tet4Coords& x) {
  Tet10Coords y;
  y.leftCols<4>() = x;
  for (int e = 0; e < 6; ++e) {
    y.col(4 + e) = 0.5 * (x.col(tet_edges[e][0]) + x.col(tet_edges[e][1]));
  }
  return y;
}

/// A tet10 with curved edges: mid-edge nodes pushed off their midpoints by a few % of the size.
inline Tet10Coords curved_tet10() {
  Tet10Coords y = straight_tet10(distorted_tet4());
  y.col(4) += Eigen::Vector3d(0.0004, -0.0006, 0.0003);
  y.col(5) += Eigen::Vector3d(-0.0005, 0.0002, 0.0004);
  y.col(7) += Eigen::Vector3d(0.0003, 0.0005, -0.0002);
  y.col(9) += Eigen::Vector3d(-0.0002, -0.0003, 0.0006);
  return y;
}

}  // namespace tt::solvers::kernels::testing
