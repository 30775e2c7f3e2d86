// Where to put temperature sensors (thermotwin place, docs/placement.md): every placement method
// for each of the case's targets and m = 1..m_max on the candidates' histories, optionally on the
// readings the campaign's sensors would give (their noise), and, for placement for estimation, on
// the physics observer's covariance model of a twin. SI units.
#pragma once

#include <optional>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "placement/place.hpp"
#include "solvers/observer.hpp"
#include "solvers/twin.hpp"
#include "studies/catalogue_detection.hpp"
#include "studies/estimation_input.hpp"
#include "studies/histories.hpp"

namespace tt::studies {

struct PlaceInput {
  const core::CaseSpec* spec = nullptr;  /// its seed drives every random draw
  Histories histories;                   /// the candidates' exact (simulated) histories
  std::vector<placement::Method> methods;
  int samples = 100, bins = 20, m_max = 6;
  /// place on readings with the campaign's sensor noise (fitting::SensorNoise), reproducible from
  /// the case's seed: exact histories of a field driven by a few sources lie in a subspace of few
  /// dimensions, beyond whose rank no further sensor is admissible
  bool sensor_noise = false;
  /// the reduced model whose observer observer_variance places for (give it when that method is
  /// asked for); nullptr: no estimation problem
  const solvers::Twin* twin = nullptr;
  /// the case's mesh, for placement for detection of the calibration catalogue's effects (the
  /// candidates are read at their positions on it); nullptr: not asked for
  const mesh::TetMesh* catalogue_mesh = nullptr;
  /// the sizes at which catalogue_mesh's detection asks to see each kind
  CatalogueSizes catalogue_sizes;
  /// gets the simulated time over the total as the catalogue's effects are marched
  solvers::Progress catalogue_progress;
  /// gets a line as each stage starts (the observer's covariance, the methods, detection)
  Progress progress;
};

/// The observer's settings for placement for estimation.
struct EstimationSettings {
  int order = 0;  /// the twin's reduced states
  double reading_interval_s = 0;
  double sensor_sigma_k = 0;     /// white noise of every reading [K]
  solvers::ObserverNoise noise;  /// its default process noise
};

/// Placement for detection beside observer_variance: where the observer's unknown inputs would
/// show (studies::observer_detection_problem on the same covariance model).
struct DetectionReport {
  DetectionSizes sizes;
  double bound_sigmas = 0;  /// the declared-run test's bound (ConsistencyOptions defaults)
  double sustain_s = 0;
  placement::DetectionProblem problem;
  placement::GreedyPath greedy;  /// from no sensor, up to m_max: effects seen after each step
  /// per target: the effects its observer_variance set of the largest m leaves unseen
  std::vector<std::pair<std::string, std::vector<int>>> unseen_by_estimation;
};

/// Up to this many candidates the catalogue's effects are marched on the reduced model on their
/// rows; beyond, in full order (each candidate's row adds Krylov vectors to the basis).
inline constexpr std::size_t kCatalogueReducedCandidates = 64;

/// Placement for detection of the calibration catalogue's heat-flow effects
/// (studies::catalogue_detection on the case's duty cycle, read at its output interval), each
/// kind counted once.
struct CatalogueDetectionReport {
  CatalogueDetectionInput settings;  /// sizes, patches, sigma, readings (names and points left out)
  double bound_sigmas = 0;           /// the declared-run test's bound (ConsistencyOptions defaults)
  placement::DetectionProblem problem;
  placement::GreedyPath greedy;  /// from no sensor, up to m_max: kinds seen after each step
  /// per target and method: the kinds its set of the largest m sees
  std::vector<std::pair<std::string, std::vector<std::pair<std::string, double>>>> kinds_seen;
};

struct PlaceReport {
  Histories histories;  /// as placed on: with the sensor noise when it was asked for
  placement::PlacementResult result;
  std::optional<EstimationSettings> estimation;                 /// with observer_variance
  std::optional<DetectionReport> detection;                     /// with observer_variance
  std::optional<CatalogueDetectionReport> catalogue_detection;  /// with catalogue_mesh
  double place_s = 0;                                           /// wall time of the placement [s]
};

/// The histories as one placement input: candidates numbered 1.. in their order.
placement::PlacementInput placement_input(const Histories& h);

/// Throws what placement::place_all throws. observer_variance without a twin places nothing.
PlaceReport place_sensors(const PlaceInput& input);

}  // namespace tt::studies
