// Placement for estimation: the sensors that make a Kalman filter's posterior variance of the
// targets (the drift at the tool) smallest, averaged over the readings of a set of runs. The
// filter's covariance does not depend on the readings' values, only on which sensors read and on
// the noise model, so the criterion is known before any sensor is installed.
//
// Plain matrices only (placement sees core): the covariance's map from one reading to the next
// along each run (what the observer's model gives, solvers::KalmanObserver::advance), the
// candidates' and the targets' rows on the filter's state, the readings' noise.
//
// The greedy search scores a candidate by the rank-one (Kalman measurement) update of the filter's
// posterior covariance under the sensors already chosen, at every reading: O(n^2) per candidate
// and reading, no refactorisation. The filter is then re-run once with the chosen sensor added.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <span>
#include <vector>

#include "placement/gaussian.hpp"

namespace tt::placement {

/// A linear filter's covariance along one run, without readings between: at reading k,
/// P_k^- = F_k P_{k-1}^+ F_k^T + Q_k, P_0^+ = `initial`. n = the filter's states.
struct CovarianceTrack {
  Eigen::MatrixXd initial;                   ///< n x n covariance at the start
  std::vector<Eigen::MatrixXd> transitions;  ///< per reading: n x n F_k from the one before
  std::vector<Eigen::MatrixXd> process;      ///< per reading: n x n Q_k accumulated since then
};

struct EstimationProblem {
  std::vector<CovarianceTrack> tracks;  ///< one per run (duty cycle)
  Eigen::MatrixXd candidate_rows;       ///< #candidates x n: a candidate's reading = row x [K]
  Eigen::VectorXd candidate_sigma;      ///< #candidates: white noise of a reading [K]
  Eigen::MatrixXd target_rows;          ///< #targets x n: a target = row x [m]
};

/// Throws core::DataError naming the first inconsistency (sizes, non-finite values, a sigma that
/// is not > 0, a run without readings) for a problem on `candidates` candidates and `targets`
/// targets.
void validate(const EstimationProblem& problem, Eigen::Index candidates, Eigen::Index targets);

/// Kalman's update of a covariance by one reading y = h x + v, var v = sigma2:
/// P - (P h)(P h)^T / (h^T P h + sigma2). O(n^2).
Eigen::MatrixXd updated_covariance(const Eigen::MatrixXd& p, const Eigen::VectorXd& h,
                                   double sigma2);

/// Each target's posterior variance with the candidates `columns` reading together at every
/// reading, averaged over the readings of all tracks: #targets [m^2]. The readings update the
/// covariance in one batch (a Cholesky factor of H P H^T + R), a computation of its own that the
/// greedy's rank-one updates are checked against.
Eigen::VectorXd mean_posterior_variance(const EstimationProblem& problem,
                                        std::span<const int> columns);

/// Greedy forward selection over `pool` (candidate columns) minimising the mean posterior
/// variance of `targets` (indices into the target rows; their variances summed), up to m_max
/// sensors or until no candidate lowers it. Each step runs the filter once under the sensors
/// chosen and scores every candidate by the reduction its reading would make at each reading,
/// the rank-one update of the posterior covariance there (a one-step look-ahead: the sensor's
/// information carried to later readings is not counted in its score, only in the criterion).
/// `scores` is the exact criterion of the set after each step [m^2]; exact ties go to the lower
/// column. `admissible(chosen, candidate)`, when given, vetoes a candidate (the other methods'
/// collinearity guard); the best admissible one is taken.
using Admissible = std::function<bool(std::span<const int> chosen, int candidate)>;
GreedyPath estimation_greedy(const EstimationProblem& problem, std::span<const int> pool, int m_max,
                             std::span<const int> targets, const Admissible& admissible = {});

}  // namespace tt::placement
