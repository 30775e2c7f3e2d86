#include "solvers/kernels/quadrature.hpp"

#include <cmath>

namespace tt::solvers::kernels {

namespace {

/// Appends the 4 points with barycentric coordinates (1 - 3a, a, a, a) and permutations.
template <int Points>
void add_tet_orbit_31(TetRule<Points>& rule, int& next, double a, double weight) {
  const Eigen::Vector4d base(1.0 - 3.0 * a, a, a, a);
  for (int k = 0; k < 4; ++k) {
    Eigen::Vector4d l = Eigen::Vector4d::Constant(a);
    l(k) = base(0);
    rule.points.col(next) = l.tail<3>();
    rule.weights(next) = weight;
    ++next;
  }
}

/// Appends the 6 points with barycentric coordinates (a, a, 1/2 - a, 1/2 - a) and permutations.
template <int Points>
void add_tet_orbit_22(TetRule<Points>& rule, int& next, double a, double weight) {
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      Eigen::Vector4d l = Eigen::Vector4d::Constant(0.5 - a);
      l(i) = a;
      l(j) = a;
      rule.points.col(next) = l.tail<3>();
      rule.weights(next) = weight;
      ++next;
    }
  }
}

/// Appends the 3 points with barycentric coordinates (1 - 2a, a, a) and permutations.
template <int Points>
void add_tri_orbit_21(TriRule<Points>& rule, int& next, double a, double weight) {
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d l = Eigen::Vector3d::Constant(a);
    l(k) = 1.0 - 2.0 * a;
    rule.points.col(next) = l.tail<2>();
    rule.weights(next) = weight;
    ++next;
  }
}

}  // namespace

const TetRule<1>& tet_rule_degree1() {
  static const TetRule<1> rule = [] {
    TetRule<1> r;
    r.degree = 1;
    r.points.col(0).setConstant(0.25);
    r.weights(0) = 1.0 / 6.0;
    return r;
  }();
  return rule;
}

const TetRule<4>& tet_rule_degree2() {
  static const TetRule<4> rule = [] {
    TetRule<4> r;
    r.degree = 2;
    int next = 0;
    add_tet_orbit_31(r, next, (5.0 - std::sqrt(5.0)) / 20.0, 1.0 / 24.0);
    return r;
  }();
  return rule;
}

const TetRule<8>& tet_rule_degree3() {
  static const TetRule<8> rule = [] {
    TetRule<8> r;
    r.degree = 3;
    int next = 0;
    add_tet_orbit_31(r, next, 1.0 / 8.0, 2.0 / 75.0);
    add_tet_orbit_31(r, next, 1.0 / 3.0, 3.0 / 200.0);
    return r;
  }();
  return rule;
}

const TetRule<14>& tet_rule_degree5() {
  // Orbit parameters and weights solved to 20 digits from the moment equations of the
  // S4-invariant polynomials of degree <= 5.
  static const TetRule<14> rule = [] {
    TetRule<14> r;
    r.degree = 5;
    int next = 0;
    add_tet_orbit_31(r, next, 0.092735250310891226402, 0.012248840519393658257);
    add_tet_orbit_31(r, next, 0.31088591926330060980, 0.018781320953002641800);
    add_tet_orbit_22(r, next, 0.045503704125649649492, 0.0070910034628469110730);
    return r;
  }();
  return rule;
}

const TriRule<1>& tri_rule_degree1() {
  static const TriRule<1> rule = [] {
    TriRule<1> r;
    r.degree = 1;
    r.points.col(0).setConstant(1.0 / 3.0);
    r.weights(0) = 0.5;
    return r;
  }();
  return rule;
}

const TriRule<3>& tri_rule_degree2() {
  static const TriRule<3> rule = [] {
    TriRule<3> r;
    r.degree = 2;
    int next = 0;
    add_tri_orbit_21(r, next, 1.0 / 6.0, 1.0 / 6.0);
    return r;
  }();
  return rule;
}

const TriRule<6>& tri_rule_degree4() {
  static const TriRule<6> rule = [] {
    TriRule<6> r;
    r.degree = 4;
    int next = 0;
    add_tri_orbit_21(r, next, 0.44594849091596488632, 0.11169079483900573285);
    add_tri_orbit_21(r, next, 0.091576213509770743460, 0.054975871827660933819);
    return r;
  }();
  return rule;
}

}  // namespace tt::solvers::kernels
