// The linear-Gaussian view of placement: if the error and the temperatures were jointly Gaussian,
// I(Y; T_S) = −½·log2(1 − R²) with R² of the least-squares fit of Y on the set S. Also the guard
// every method shares against choosing two collinear sensors (mirror twins) as if they were two.
#pragma once

#include <Eigen/Dense>
#include <optional>
#include <span>
#include <vector>

namespace tt::placement {

struct LinearProblem {
  Eigen::MatrixXd z;    ///< #samples x #candidates centred unit-norm histories (z_i·z_j = r_ij)
  Eigen::VectorXd y;    ///< #samples centred unit-norm error
  Eigen::VectorXd r_y;  ///< #candidates correlation coefficient of each candidate with the error
};

/// temperatures: #samples x #candidates; error: #samples.
LinearProblem linear_problem(const Eigen::MatrixXd& temperatures, const Eigen::VectorXd& error);

/// −½·log2(1 − R²) [bits], R² clamped below 1 − 1e-15 so that an exact fit stays finite.
double gaussian_mi_bits(double r_squared);

/// When a candidate is not a sensor of its own: a mirror twin or a combination of chosen ones.
struct Collinearity {
  double max_correlation = 0.999;  ///< |r| with one chosen sensor above this: a twin
  double min_residual = 1e-8;      ///< share of its variance left after projection on the chosen
};

/// Whether candidate c adds a direction to `chosen`: its correlation with each chosen history is
/// at most guard.max_correlation and the share of its variance left after projection on all of
/// them is at least guard.min_residual. A constant history never does.
bool adds_direction(const LinearProblem& problem, std::span<const int> chosen, int c,
                    const Collinearity& guard);

/// R² of the fit of the error on the candidates in `set` (with intercept), or nothing when a
/// member does not add a direction to the members before it (see adds_direction).
std::optional<double> set_r_squared(const LinearProblem& problem, std::span<const int> set,
                                    const Collinearity& guard);

/// A forward selection: the set for m is the first m entries of `order`.
struct GreedyPath {
  std::vector<int> order;       ///< candidate columns in the order chosen
  std::vector<double> scores;   ///< the criterion after each step [bits unless said otherwise]
  std::vector<double> seconds;  ///< wall time from the start to each step [s]
};

/// Greedy forward selection maximising R² (equivalently the Gaussian MI) over `pool`, up to m_max
/// sensors or until no admissible candidate is left; exact ties go to the lower column.
GreedyPath gaussian_greedy(const LinearProblem& problem, std::span<const int> pool, int m_max,
                           const Collinearity& guard);

}  // namespace tt::placement
