// Geometry of the reference elements: shape functions, Jacobians, point location and face
// geometry for 4- and 10-node tets and 3- and 6-node triangles. Pure functions on fixed-size
// Eigen types (no heap, no state), called once per element and quadrature point in assembly.
//
// Node order is VTK's, fixed project-wide:
//   tet4  corners 0..3;
//   tet10 corners 0..3, then mid-edge nodes on (0,1) (1,2) (0,2) (0,3) (1,3) (2,3);
//   tri3  corners 0..2;
//   tri6  corners 0..2, then mid-edge nodes on (0,1) (1,2) (2,0).
// Natural coordinates are VTK's parametric ones: on the tet xi = (r, s, t) with node 0 at the
// origin, node 1 at r = 1, node 2 at s = 1, node 3 at t = 1, and barycentric coordinates
// L = (1 - r - s - t, r, s, t); on the triangle xi = (r, s), L = (1 - r - s, r, s).
//
// Errors: every function that needs a positive Jacobian takes `element`, the element's index in
// the mesh (used only in the message), and throws tt::core::SolverError naming it when
// det J <= 0, or is positive only by rounding: det J <= 1e-12 x |J e_r| |J e_s| |J e_t| (the
// ratio is about 0.7 for a regular tet). Faces likewise take `face`. Exceptions must not escape an
// OpenMP region: an assembler that calls kernels inside core::parallel_for/parallel_chunks must
// catch there (e.g. keep a std::exception_ptr per chunk and rethrow after the loop), or check every
// element first with `min_jacobian_determinant`.
#pragma once

#include <Eigen/Core>
#include <array>

namespace tt::solvers::kernels {

/// 3 x 4 node coordinates of a linear tet, one column per node [m]
using Tet4Coords = Eigen::Matrix<double, 3, 4>;
/// 3 x 10 node coordinates of a quadratic tet, one column per node [m]
using Tet10Coords = Eigen::Matrix<double, 3, 10>;
/// 3 x 3 node coordinates of a linear triangle, one column per node [m]
using Tri3Coords = Eigen::Matrix<double, 3, 3>;
/// 3 x 6 node coordinates of a quadratic triangle, one column per node [m]
using Tri6Coords = Eigen::Matrix<double, 3, 6>;

/// Local corner nodes of the tet's edges, in the order of the tet10 mid-edge nodes 4..9.
inline constexpr std::array<std::array<int, 2>, 6> tet_edges = {
    {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}}};
/// Face k of a tet4 is the one opposite corner k; its nodes follow the right hand around the
/// outward normal (for a tet with positive det J).
inline constexpr std::array<std::array<int, 3>, 4> tet4_faces = {
    {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};
/// tet4_faces with the tri6 mid-edge nodes appended in tri6 order (edges (0,1) (1,2) (2,0) of
/// the face).
inline constexpr std::array<std::array<int, 6>, 4> tet10_faces = {
    {{1, 2, 3, 5, 9, 8}, {0, 3, 2, 7, 9, 6}, {0, 1, 3, 4, 8, 7}, {0, 2, 1, 6, 5, 4}}};

// ---- Shape functions in natural coordinates --------------------------------------------------

/// Barycentric coordinates (1 - r - s - t, r, s, t) of the natural point xi = (r, s, t).
Eigen::Vector4d tet_barycentric_of_natural(const Eigen::Vector3d& xi);

/// 4 linear shape functions at xi (= barycentric coordinates).
Eigen::Vector4d tet4_shape(const Eigen::Vector3d& xi);
/// 4 x 3 derivatives dN_i/dxi_j of the linear shape functions (constant).
Eigen::Matrix<double, 4, 3> tet4_shape_derivatives();

/// 10 quadratic shape functions at xi: corners L_i (2 L_i - 1), mid-edge 4 L_i L_j.
Eigen::Matrix<double, 10, 1> tet10_shape(const Eigen::Vector3d& xi);
/// 10 x 3 derivatives dN_i/dxi_j of the quadratic shape functions at xi.
Eigen::Matrix<double, 10, 3> tet10_shape_derivatives(const Eigen::Vector3d& xi);
/// 3 x 10 natural coordinates of the tet10 nodes (the first 4 columns are the tet4 nodes).
Eigen::Matrix<double, 3, 10> tet10_node_natural();

/// 3 linear triangle shape functions at xi = (r, s).
Eigen::Vector3d tri3_shape(const Eigen::Vector2d& xi);
/// 3 x 2 derivatives dN_i/dxi_j of the linear triangle shape functions (constant).
Eigen::Matrix<double, 3, 2> tri3_shape_derivatives();
/// 6 quadratic triangle shape functions at xi = (r, s).
Eigen::Matrix<double, 6, 1> tri6_shape(const Eigen::Vector2d& xi);
/// 6 x 2 derivatives dN_i/dxi_j of the quadratic triangle shape functions at xi.
Eigen::Matrix<double, 6, 2> tri6_shape_derivatives(const Eigen::Vector2d& xi);

// ---- Jacobians and physical gradients --------------------------------------------------------

/// J_ab = dx_a/dxi_b of the linear tet (constant); det J = 6 x signed volume [m^3].
Eigen::Matrix3d jacobian(const Tet4Coords& x);
/// J_ab = dx_a/dxi_b of the quadratic tet at xi.
Eigen::Matrix3d jacobian(const Tet10Coords& x, const Eigen::Vector3d& xi);

/// Smallest det J [m^3] over the nodes and the quadrature points the kernels use, with a point
/// where the element is flat to rounding (see above) counted as <= 0: the kernels accept the
/// element iff this is > 0. Never throws: meant for a serial validity pass before assembly.
double min_jacobian_determinant(const Tet4Coords& x);
double min_jacobian_determinant(const Tet10Coords& x);

/// Shape-function gradients in physical space and det J at one point.
template <int Nodes>
struct ShapeGradients {
  Eigen::Matrix<double, Nodes, 3> dn_dx;  /// #nodes x 3, dN_i/dx_j [1/m]
  double det_j = 0.0;                     /// det J [m^3] (6 x volume for a straight tet)
};

/// Physical gradients of the linear tet (constant). Throws SolverError if det J <= 0.
ShapeGradients<4> tet4_gradients(const Tet4Coords& x, int element);
/// Physical gradients of the quadratic tet at xi. Throws SolverError if det J(xi) <= 0.
ShapeGradients<10> tet10_gradients(const Tet10Coords& x, const Eigen::Vector3d& xi, int element);

// ---- Point location --------------------------------------------------------------------------

/// Barycentric coordinates (sum 1) of point p [m] in the straight-sided tet with corners x; p lies
/// in the closed tet iff all are >= 0 (compare with a tolerance, e.g. -1e-10). Throws SolverError
/// if the tet is degenerate or inverted.
Eigen::Vector4d tet_barycentric(const Tet4Coords& x, const Eigen::Vector3d& p, int element);
/// Same, from the corner columns of a tet10.
Eigen::Vector4d tet_barycentric(const Tet10Coords& x, const Eigen::Vector3d& p, int element);

/// Interpolation weights of the 4 nodes at point p: a nodal field f has value weights . f at p.
Eigen::Vector4d tet4_weights_at(const Tet4Coords& x, const Eigen::Vector3d& p, int element);
/// Interpolation weights of the 10 nodes at point p, for a tet10 with straight edges (mid-edge
/// nodes at the midpoints, as TetGen makes them); p is located with the corners only.
Eigen::Matrix<double, 10, 1> tet10_weights_at(const Tet10Coords& x, const Eigen::Vector3d& p,
                                              int element);

// ---- Face geometry ---------------------------------------------------------------------------

/// Area [m^2] of a triangle face.
double face_area(const Tri3Coords& x);
/// Area [m^2] of a quadratic triangle face (by quadrature, so curved edges are honoured).
double face_area(const Tri6Coords& x);
/// Unit normal of the plane of the face's corners, right hand around nodes 0, 1, 2 (outward
/// for faces from tet4_faces/tet10_faces or TetMesh::faces). Throws SolverError if the face
/// has zero area.
Eigen::Vector3d face_normal(const Tri3Coords& x, int face);
Eigen::Vector3d face_normal(const Tri6Coords& x, int face);

}  // namespace tt::solvers::kernels
