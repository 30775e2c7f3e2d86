// Every quadrature rule integrates every monomial up to its degree exactly, and not one degree
// more (so the stated degree is the true one).
#include <gtest/gtest.h>

#include <cmath>

#include "solvers/kernels/quadrature.hpp"

namespace tt::solvers::kernels {
namespace {

double factorial(int n) {
  return n <= 1 ? 1.0 : n * factorial(n - 1);
}

/// integral over the reference tet of r^a s^b t^c
double tet_monomial(int a, int b, int c) {
  return factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3);
}
/// integral over the reference triangle of r^a s^b
double tri_monomial(int a, int b) {
  return factorial(a) * factorial(b) / factorial(a + b + 2);
}

/// Largest relative error of the rule over all monomials of total degree exactly `degree`.
template <int P>
double tet_error(const TetRule<P>& rule, int degree) {
  double worst = 0.0;
  for (int a = 0; a <= degree; ++a) {
    for (int b = 0; a + b <= degree; ++b) {
      const int c = degree - a - b;
      double sum = 0.0;
      for (int q = 0; q < P; ++q) {
        const Eigen::Vector3d xi = rule.points.col(q);
        sum += rule.weights(q) * std::pow(xi.x(), a) * std::pow(xi.y(), b) * std::pow(xi.z(), c);
      }
      const double exact = tet_monomial(a, b, c);
      worst = std::max(worst, std::abs(sum - exact) / exact);
    }
  }
  return worst;
}

template <int P>
double tri_error(const TriRule<P>& rule, int degree) {
  double worst = 0.0;
  for (int a = 0; a <= degree; ++a) {
    const int b = degree - a;
    double sum = 0.0;
    for (int q = 0; q < P; ++q) {
      sum += rule.weights(q) * std::pow(rule.points(0, q), a) * std::pow(rule.points(1, q), b);
    }
    const double exact = tri_monomial(a, b);
    worst = std::max(worst, std::abs(sum - exact) / exact);
  }
  return worst;
}

template <int P>
void expect_tet_rule(const TetRule<P>& rule, int degree) {
  EXPECT_EQ(rule.degree, degree);
  for (int d = 0; d <= degree; ++d) EXPECT_LT(tet_error(rule, d), 1e-13) << "degree " << d;
  EXPECT_GT(tet_error(rule, degree + 1), 1e-6) << "rule is exact beyond its stated degree";
  for (int q = 0; q < P; ++q) {
    EXPECT_GT(rule.weights(q), 0.0);
    const Eigen::Vector3d xi = rule.points.col(q);
    EXPECT_GE(xi.minCoeff(), 0.0);
    EXPECT_LE(xi.sum(), 1.0 + 1e-15);
  }
}

template <int P>
void expect_tri_rule(const TriRule<P>& rule, int degree) {
  EXPECT_EQ(rule.degree, degree);
  for (int d = 0; d <= degree; ++d) EXPECT_LT(tri_error(rule, d), 1e-13) << "degree " << d;
  EXPECT_GT(tri_error(rule, degree + 1), 1e-6) << "rule is exact beyond its stated degree";
  for (int q = 0; q < P; ++q) {
    EXPECT_GT(rule.weights(q), 0.0);
    EXPECT_GE(rule.points.col(q).minCoeff(), 0.0);
    EXPECT_LE(rule.points.col(q).sum(), 1.0 + 1e-15);
  }
}

TEST(Quadrature, TetDegree1) {
  expect_tet_rule(tet_rule_degree1(), 1);
}
TEST(Quadrature, TetDegree2) {
  expect_tet_rule(tet_rule_degree2(), 2);
}
TEST(Quadrature, TetDegree3) {
  expect_tet_rule(tet_rule_degree3(), 3);
}
TEST(Quadrature, TetDegree5) {
  expect_tet_rule(tet_rule_degree5(), 5);
}
TEST(Quadrature, TriDegree1) {
  expect_tri_rule(tri_rule_degree1(), 1);
}
TEST(Quadrature, TriDegree2) {
  expect_tri_rule(tri_rule_degree2(), 2);
}
TEST(Quadrature, TriDegree4) {
  expect_tri_rule(tri_rule_degree4(), 4);
}

}  // namespace
}  // namespace tt::solvers::kernels
