// Quadrature rules on the reference tet and triangle, in the natural coordinates of element.hpp.
// Weights sum to the reference measure (1/6 for the tet, 1/2 for the triangle), so that
//   integral over the element of f = sum_q weights(q) * f(points.col(q)) * |det J(points.col(q))|.
// All weights are positive. Each rule is checked in tests to integrate every monomial up to its
// degree exactly. The rules are immutable tables built on first use (thread-safe).
#pragma once

#include <Eigen/Core>

namespace tt::solvers::kernels {

template <int Points>
struct TetRule {
  int degree = 0;                            /// polynomial degree integrated exactly
  Eigen::Matrix<double, 3, Points> points;   /// natural coordinates (r, s, t), one per column
  Eigen::Matrix<double, Points, 1> weights;  /// sum = 1/6
};

template <int Points>
struct TriRule {
  int degree = 0;                            /// polynomial degree integrated exactly
  Eigen::Matrix<double, 2, Points> points;   /// natural coordinates (r, s), one per column
  Eigen::Matrix<double, Points, 1> weights;  /// sum = 1/2
};

/// Centroid rule, degree 1.
const TetRule<1>& tet_rule_degree1();
/// 4 points at barycentric (b, a, a, a) and permutations, a = (5 - sqrt 5)/20; degree 2.
const TetRule<4>& tet_rule_degree2();
/// 8 points, degree 3, positive weights: (5/8, 1/8, 1/8, 1/8) and permutations with weight
/// 2/75 each, and the face centroids (0, 1/3, 1/3, 1/3) and permutations with weight 3/200 each.
/// (Keast's 5-point degree-3 rule has a negative centroid weight, hence this one.)
const TetRule<8>& tet_rule_degree3();
/// 14 points, degree 5, positive weights (two 4-point orbits and one 6-point edge orbit); used
/// wherever degree 4 or 5 is needed.
const TetRule<14>& tet_rule_degree5();

/// Centroid rule, degree 1.
const TriRule<1>& tri_rule_degree1();
/// 3 points at barycentric (2/3, 1/6, 1/6) and permutations, degree 2.
const TriRule<3>& tri_rule_degree2();
/// 6 points (two 3-point orbits), degree 4, positive weights.
const TriRule<6>& tri_rule_degree4();

}  // namespace tt::solvers::kernels
