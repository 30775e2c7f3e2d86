// Baselines from practice: ranking by the correlation coefficient with the error
// (DB3401/T 326-2024, 7.1) and grey relational analysis (seed 004).
#pragma once

#include <Eigen/Dense>
#include <span>
#include <vector>

#include "placement/gaussian.hpp"

namespace tt::placement {

/// Grey relational grade of each candidate with the error, on z-scored series:
/// ξ_i(k) = (Δmin + ρ·Δmax) / (Δ_i(k) + ρ·Δmax), Δ_i(k) = |y(k) − x_i(k)|, Δmin and Δmax over
/// every candidate and sample; the grade is the mean of ξ_i(k) over k. ρ in (0, 1], usually 0.5.
/// temperatures: #samples x #candidates; error: #samples. Returns #candidates grades in (0, 1].
Eigen::VectorXd grey_relational_grades(const Eigen::MatrixXd& temperatures,
                                       const Eigen::VectorXd& error, double rho);

/// The m best of `pool` by `scores` (#candidates, larger is better; exact ties to the lower
/// column), skipping candidates that do not add a direction to those already taken.
std::vector<int> top_ranked(const Eigen::VectorXd& scores, std::span<const int> pool, int m,
                            const LinearProblem& linear, const Collinearity& guard);

/// 1-based rank of every candidate by descending score, exact ties to the lower column.
std::vector<int> ranks_descending(const Eigen::VectorXd& scores);

}  // namespace tt::placement
