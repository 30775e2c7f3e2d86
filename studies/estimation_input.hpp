// Placement for estimation on a twin: the physics observer's covariance model
// (solvers::KalmanObserver) as the plain matrices placement::estimation_greedy takes, over a set
// of duty cycles (docs/placement.md, "Placement for estimation").
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "placement/detection.hpp"
#include "placement/estimation.hpp"
#include "solvers/observer.hpp"
#include "solvers/twin.hpp"
#include "studies/progress.hpp"

namespace tt::studies {

/// The observer's covariance along `run`'s duty cycle read at `times` [s] (increasing, after 0,
/// within the duty cycle) under `setup`'s process noise: the map from each reading to the next,
/// which no reading changes. Throws SolverError as solvers::KalmanObserver does.
placement::CovarianceTrack observer_covariance_track(const solvers::ReducedThermalSystem& system,
                                                     const core::CaseSpec& run,
                                                     const solvers::ObserverSetup& setup,
                                                     const Eigen::VectorXd& times);

/// Readings every `sample_s` from sample_s to the duty cycle's end. Throws SolverError when
/// sample_s is not > 0.
Eigen::VectorXd reading_times(const core::CaseSpec& run, double sample_s);

/// The readings a change must stay beyond the bound over to be held for `sustain_s` when read
/// every `sample_s`: the first and the last sustain_s apart (solvers::HeldBeyondMonitor raises at
/// t - since >= sustain_s).
int sustain_readings(double sustain_s, double sample_s);

/// Candidates of an estimation problem on a twin: a named point of the twin reads through its
/// output row; any other candidate through the reduced basis's row of its mesh node.
struct EstimationCandidates {
  std::vector<std::string> names;  /// #candidates
  std::vector<int> nodes;          /// #candidates mesh node, -1 when not known
  double sensor_sigma_k = 0.05;    /// white noise of every reading [K]
};

/// The observer's estimation problem on `twin` over `runs` (their duty cycles, each read every
/// `sample_s`): the covariance tracks, the candidates' rows and sigmas, and the rows of the
/// targets `targets` (names of the observer's targets: "dx", "dy", "dz", "<axis point>_dy", ...),
/// each scaled by noise.drift_sigma_scale when that is set (one factor per observer target).
/// `progress`, when given, gets a line as each run's track is done (the long part: the
/// covariance stepped along the run). Throws SolverError for a candidate that is neither a named
/// point nor a node of the twin's basis, an unknown target, or no run.
placement::EstimationProblem observer_estimation_problem(
    const solvers::Twin& twin, const std::vector<core::CaseSpec>& runs,
    const EstimationCandidates& candidates, const std::vector<std::string>& targets,
    const solvers::ObserverNoise& noise, double sample_s, const Progress& progress = {});

/// The sizes at which placement for detection asks to see the observer's unknown inputs: a
/// heat input at a source or film [W], the air's offset [K].
struct DetectionSizes {
  double heat_w = 5;
  double air_k = 1;
};

/// Placement for detection on `problem` (observer_estimation_problem's, its runs read every
/// `sample_s`): each of the observer's unknown heat inputs and its air (not the sensors'
/// offsets) held at `sizes` from t = 0, and how far it moves each candidate's reading from the
/// declared run for `sustain_s` (solvers::ConsistencyOptions::sustain_s), in sigmas. `run` and
/// `noise` as the problem was built with. Throws SolverError when sample_s or sustain_s is not
/// > 0, DataError as placement::detection_problem does.
placement::DetectionProblem observer_detection_problem(const solvers::Twin& twin,
                                                       const placement::EstimationProblem& problem,
                                                       const core::CaseSpec& run,
                                                       const solvers::ObserverNoise& noise,
                                                       const DetectionSizes& sizes,
                                                       double sustain_s, double sample_s);

}  // namespace tt::studies
