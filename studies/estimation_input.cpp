#include "studies/estimation_input.hpp"

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"

namespace tt::studies {

placement::CovarianceTrack observer_covariance_track(const solvers::ReducedThermalSystem& system,
                                                     const core::CaseSpec& run,
                                                     const solvers::ObserverSetup& setup,
                                                     const Eigen::VectorXd& times) {
  solvers::KalmanObserver observer(system, run, setup);
  placement::CovarianceTrack track;
  track.initial = observer.covariance();
  for (const double t : times) {
    solvers::CovarianceMap map = observer.advance(t);
    track.transitions.push_back(std::move(map.transition));
    track.process.push_back(std::move(map.process));
  }
  return track;
}

Eigen::VectorXd reading_times(const core::CaseSpec& run, double sample_s) {
  if (!(sample_s > 0))
    throw core::SolverError("estimation placement: readings every " + std::to_string(sample_s) +
                            " s: expected > 0");
  const auto count = static_cast<Eigen::Index>(run.duty_cycle.end / sample_s + 1e-9);
  return Eigen::VectorXd::LinSpaced(count, sample_s, static_cast<double>(count) * sample_s);
}

int sustain_readings(double sustain_s, double sample_s) {
  return static_cast<int>(std::ceil(sustain_s / sample_s - 1e-9)) + 1;
}

namespace {

/// A candidate's row on the reduced state (r columns).
Eigen::RowVectorXd candidate_row(const solvers::Twin& twin, const std::string& name, int node) {
  if (const int row = solvers::temperature_row(twin.outputs, name); row >= 0)
    return twin.outputs.rows.row(row);
  if (node >= 0 && node < twin.model.basis.rows()) return twin.model.basis.row(node);
  throw core::SolverError("estimation placement: candidate '" + name + "' (node " +
                          std::to_string(node) +
                          ") is neither a named point of the reduced model nor a node of its "
                          "basis (" +
                          std::to_string(twin.model.basis.rows()) + " nodes)");
}

/// The observer's set-up on `twin` for `run` with no sensor: what the covariance model and the
/// unknown inputs need (`noise` without its sensors' sigmas).
solvers::ObserverSetup sensorless_setup(const solvers::Twin& twin, const core::CaseSpec& run,
                                        const solvers::ObserverNoise& noise) {
  solvers::ObserverNoise without_sensors = noise;
  without_sensors.sensor_sigma_k.resize(0);
  return solvers::twin_observer_setup(twin, run, {}, without_sensors);
}

}  // namespace

placement::EstimationProblem observer_estimation_problem(
    const solvers::Twin& twin, const std::vector<core::CaseSpec>& runs,
    const EstimationCandidates& candidates, const std::vector<std::string>& targets,
    const solvers::ObserverNoise& noise, double sample_s, const Progress& progress) {
  if (runs.empty()) throw core::SolverError("estimation placement: no run to place on");
  const solvers::ObserverSetup setup = sensorless_setup(twin, runs.front(), noise);
  placement::EstimationProblem p;
  for (const auto& run : runs) {
    p.tracks.push_back(
        observer_covariance_track(twin.model.system, run, setup, reading_times(run, sample_s)));
    if (progress)
      progress("placement for estimation: the covariance stepped along duty cycle " +
               std::to_string(p.tracks.size()) + " of " + std::to_string(runs.size()));
  }
  // The filter's state is [z; unknown inputs]: the rows read z only.
  const Eigen::Index r = twin.model.states(), n = p.tracks.front().initial.rows();
  const auto count = static_cast<Eigen::Index>(candidates.names.size());
  p.candidate_rows = Eigen::MatrixXd::Zero(count, n);
  for (Eigen::Index c = 0; c < count; ++c) {
    const auto k = static_cast<std::size_t>(c);
    p.candidate_rows.row(c).head(r) = candidate_row(
        twin, candidates.names[k], k < candidates.nodes.size() ? candidates.nodes[k] : -1);
  }
  p.candidate_sigma = Eigen::VectorXd::Constant(count, candidates.sensor_sigma_k);
  p.target_rows = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(targets.size()), n);
  for (std::size_t t = 0; t < targets.size(); ++t) {
    const auto& names = setup.target_names;
    const auto it = std::find(names.begin(), names.end(), targets[t]);
    if (it == names.end())
      throw core::SolverError("estimation placement: target '" + targets[t] +
                              "' is not one of the observer's (dx, dy, dz, axis points)");
    const auto row = it - names.begin();
    const double scale = noise.drift_sigma_scale.size() != 0 ? noise.drift_sigma_scale(row) : 1.0;
    p.target_rows.row(static_cast<Eigen::Index>(t)).head(r) = scale * setup.target_rows.row(row);
  }
  return p;
}

placement::DetectionProblem observer_detection_problem(const solvers::Twin& twin,
                                                       const placement::EstimationProblem& problem,
                                                       const core::CaseSpec& run,
                                                       const solvers::ObserverNoise& noise,
                                                       const DetectionSizes& sizes,
                                                       double sustain_s, double sample_s) {
  if (!(sample_s > 0) || !(sustain_s > 0))
    throw core::SolverError("detection placement: readings every " + std::to_string(sample_s) +
                            " s held for " + std::to_string(sustain_s) + " s: expected both > 0");
  const solvers::KalmanObserver observer(twin.model.system, run,
                                         sensorless_setup(twin, run, noise));
  const std::vector<std::string>& names = observer.unknown_inputs();
  const std::vector<solvers::UnknownInputKind> kinds = observer.unknown_input_kinds();
  std::vector<std::string> effects;
  std::vector<Eigen::Index> states;
  std::vector<double> size;
  for (std::size_t j = 0; j < names.size(); ++j) {
    if (kinds[j] == solvers::UnknownInputKind::sensor_offset) continue;
    effects.push_back(names[j]);
    states.push_back(twin.model.states() + static_cast<Eigen::Index>(j));
    size.push_back(kinds[j] == solvers::UnknownInputKind::heat ? sizes.heat_w : sizes.air_k);
  }
  return placement::detection_problem(
      problem, effects, states,
      Eigen::Map<const Eigen::VectorXd>(size.data(), static_cast<Eigen::Index>(size.size())),
      sustain_readings(sustain_s, sample_s));
}

}  // namespace tt::studies
