// Placement for detection: sensors where the machine's undeclared changes would show. The
// observer raises `recalibrate` when a reading stays more than a bound (in its sensor's sigmas)
// from the declared model's own run for a sustain time (solvers::ConsistencyOptions). An effect
// that moves no chosen sensor's reading that far for that long is never seen, however good the
// sensors are for estimating the drift at the tool.
//
// Plain matrices only (placement sees core): the filter's map from one reading to the next along
// each run (EstimationProblem's tracks, whose states are [reduced states; unknown inputs]) carries
// a constant unknown input (a heat input at a source or film, the air's offset) into the reduced
// states; the candidates' rows read the change it makes. The criterion counts the effects some
// chosen sensor would see, each at a stated size.
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "placement/estimation.hpp"
#include "placement/gaussian.hpp"

namespace tt::placement {

/// How far each effect moves each candidate's reading, held: #effects x #candidates, the largest
/// over the runs and times of the smallest |change| over `sustain_readings` consecutive readings,
/// in the candidate's sigmas, for each effect at its stated size.
struct DetectionProblem {
  std::vector<std::string> effects;  ///< #effects names
  Eigen::MatrixXd held_sigmas;       ///< #effects x #candidates
  /// #effects: what seeing each effect is worth to the greedy (empty: 1 each). One kind's places
  /// weighted 1 / #places together count as one kind whose place is drawn at random.
  Eigen::VectorXd weights;
  std::vector<std::string> kinds;  ///< #effects: each effect's kind, for reports (may be empty)
};

/// Weights that make each kind of `kinds` count once: 1 / (the number of effects of its kind).
Eigen::VectorXd weights_per_kind(const std::vector<std::string>& kinds);

/// The held changes of `problem`'s candidates under each unknown input `effect_states` (indices
/// into the tracks' states, after the reduced ones) held constant at `sizes` (one per effect, in
/// the input's unit: W, K) from t = 0, carried along every track's transitions. Throws
/// core::DataError for a state index out of range, sizes that do not match, a size that is not
/// finite and > 0, or sustain_readings < 1.
DetectionProblem detection_problem(const EstimationProblem& problem,
                                   const std::vector<std::string>& effects,
                                   std::span<const Eigen::Index> effect_states,
                                   const Eigen::VectorXd& sizes, int sustain_readings);

/// The same from the effects' own responses: `changes[e][k]` is effect e's change of every
/// candidate's reading along run k at its stated size (#readings x #candidates, in the readings'
/// unit), `sigma` each candidate's noise (#candidates, same unit); held over `sustain_readings`
/// as above. Throws core::DataError for names and changes that do not pair up, an effect with no
/// run, a change of another number of candidates than `sigma` has, a sigma that is not finite
/// and > 0, or sustain_readings < 1.
DetectionProblem detection_problem(const std::vector<std::string>& effects,
                                   const std::vector<std::vector<Eigen::MatrixXd>>& changes,
                                   const Eigen::VectorXd& sigma, int sustain_readings);

/// Greedy forward selection over `pool` added to the sensors `chosen` (already installed): at
/// each step the candidate that makes the most effects seen (held_sigmas >= bound at some chosen
/// sensor; each counted at its weight), ties broken by the most progress towards the unseen ones
/// (the sum over them of weight x min(held, bound)), exact ties to the lower column; up to m_max
/// sensors, or until no candidate adds to either. `scores` is the (weighted) number of effects
/// seen after each step. Throws core::DataError for a bound that is not finite and > 0, a column
/// out of range, or weights that are not one per effect, finite and >= 0.
GreedyPath detection_greedy(const DetectionProblem& problem, std::span<const int> chosen,
                            std::span<const int> pool, int m_max, double bound);

/// The weighted number of effects some sensor of `columns` sees at `bound` (each at its weight, 1
/// when there are none: with weights_per_kind, the kinds seen).
double seen_weight(const DetectionProblem& problem, std::span<const int> columns, double bound);

/// The effects no sensor of `columns` sees at `bound` (their indices, in order).
std::vector<int> unseen_effects(const DetectionProblem& problem, std::span<const int> columns,
                                double bound);

}  // namespace tt::placement
