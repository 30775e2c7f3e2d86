// The Kraskov–Stögbauer–Grassberger k-nearest-neighbour estimator (their algorithm 1) and the
// two selections built on it: greedy forward selection on the joint I(Y; T_S), and JMI.
// Brute force O(S²·d) per estimate: meant for tens to a few hundred candidates.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <span>
#include <vector>

#include "placement/gaussian.hpp"

namespace tt::placement {

/// KSG algorithm 1, I(X; Y) [bits]: x is #samples x d_x, y is #samples x d_y; max-norm in each
/// space, k-th neighbour in the joint space. k in [1, #samples - 1]. May be slightly negative.
double ksg_mi_bits(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, int k);

/// The histories and error prepared for KSG: unit-variance columns plus a seeded jitter of 1e-10
/// (relative) that breaks exact distance ties, as Kraskov et al. recommend.
struct KsgProblem {
  Eigen::MatrixXd x;  ///< #samples x #candidates
  Eigen::VectorXd y;  ///< #samples
  int k = 4;
};

KsgProblem ksg_problem(const LinearProblem& problem, int k, std::uint64_t seed);

/// KSG I(Y; T_set) [bits] for candidate columns `set`.
double ksg_set_bits(const KsgProblem& problem, std::span<const int> set);

/// Greedy forward selection maximising the KSG joint I(Y; T_S ∪ {c}); candidates that do not add
/// a direction (`linear`, `guard`) are skipped; exact ties go to the lower column.
GreedyPath ksg_greedy(const KsgProblem& problem, const LinearProblem& linear,
                      std::span<const int> pool, int m_max, const Collinearity& guard);

/// Joint mutual information (JMI): the first sensor maximises I(Y; T_c); each next one maximises
/// Σ_{s chosen} I(Y; T_c, T_s), each term a 2-D KSG estimate. scores hold the KSG joint
/// I(Y; T_S) of each prefix, so they compare with ksg_greedy.
GreedyPath jmi_greedy(const KsgProblem& problem, const LinearProblem& linear,
                      std::span<const int> pool, int m_max, const Collinearity& guard);

}  // namespace tt::placement
