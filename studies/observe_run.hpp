// The physics observer (docs/observer.md) on a measured run, as `thermotwin observe` runs it: a
// Kalman filter on a reduced model's states, fed with the run's spindle speed (its speed_rpm
// column) as the duty cycle and its sensors' readings, that predicts the drift at the tool (and the
// axis points) with its standard deviation and says when the innovations stop fitting the noise
// model. SI units.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "io/measured_data.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/observer.hpp"
#include "solvers/twin.hpp"

namespace tt::studies {

/// The ids of `ids` that are named points of the twin (its temperature outputs), in their order.
std::vector<std::string> named_by_twin(const solvers::TwinOutputs& outputs,
                                       const std::vector<std::string>& ids);

/// The observer's set-up on the case under a run, for the chosen sensors read through the given
/// rows (#sensors x the twin's states: sensor_readout's): the noise model and consistency test.
using ObserverSetupFor = std::function<solvers::ObserverSetup(
    const core::CaseSpec&, const std::vector<std::string>&, const Eigen::MatrixXd&)>;

struct ObserveInput {
  const core::CaseSpec* declared = nullptr;
  const io::MeasuredRun* run = nullptr;
  /// the reduced model, checked by the caller against the declared case and its mesh
  const solvers::Twin* twin = nullptr;
  /// the run's columns to observe; empty: every sensor of the run (not its ambient sensor) that
  /// has a position (with `mesh`) or that the twin names
  std::vector<std::string> sensors;
  ObserverSetupFor setup;
  /// the case's mesh (the twin's): a sensor the run locates (its position in meta.json) is read
  /// there, interpolated on the twin's basis, as the measured-data format says a sensor need not
  /// sit at a mesh vertex; nullptr: every sensor at the named point of its id
  const mesh::TetMesh* mesh = nullptr;
  /// > 0: the run's displacement columns whose ids name the observer's targets ("dx", "dy", "dz",
  /// "<axis point>_dy", ...) are read by the observer as drift readings, one every this many
  /// seconds (the first sample at or after each multiple: a probe cycle measuring the tool now and
  /// then); 0: the observer reads temperatures only, and the columns are its truth at most
  double drift_readings_every_s = 0;
};

/// Where a sensor was read on the model.
struct SensorPlace {
  std::optional<Eigen::Vector3d> position;  /// the run's position [m]; none: the named point
  /// distance from the twin's named point of the same id [m], when both exist
  std::optional<double> from_named_point_m;
};

struct ObserveReport {
  core::CaseSpec spec;               /// the declared case under the run's inputs
  std::vector<std::string> sensors;  /// the observed columns, in the readings' order
  std::vector<SensorPlace> places;   /// per sensor: where it was read
  solvers::ObserverSetup setup;
  solvers::ObserverRun result;
  /// with drift_readings_every_s: the targets read, and the samples that read them
  double drift_readings_every_s = 0;
  std::vector<std::string> drift_targets;
  int drift_samples = 0;
};

/// The ids of `ids` the observer can read: those `located` (a run's sensors, or a stream's
/// meta.json) gives a position (when there is a mesh) and those the twin names; not `ambient`.
std::vector<std::string> readable_sensors(const solvers::TwinOutputs& outputs,
                                          const mesh::TetMesh* mesh,
                                          const std::vector<io::MeasuredSensor>& located,
                                          const std::vector<std::string>& ids,
                                          const std::optional<std::string>& ambient);

/// Where each sensor is read, and its rows on the twin.
struct SensorReadout {
  std::vector<SensorPlace> places;
  Eigen::MatrixXd rows;  /// #sensors x the twin's states
};

/// Each of `ids` read at its position in `located` (interpolated on the twin's basis on `mesh`,
/// when there is one), else at the twin's named point of its id. Throws DataError naming
/// `source` and the sensor for one that has neither, or a position outside the mesh.
SensorReadout sensor_readout(const solvers::Twin& twin, const mesh::TetMesh* mesh,
                             const std::vector<io::MeasuredSensor>& located,
                             const std::vector<std::string>& ids, const std::string& source);

/// A run's drift readings for an observer.
struct DriftReadings {
  Eigen::MatrixXd readings;          /// #samples x #targets [m], NaN where not read; empty: none
  std::vector<std::string> targets;  /// the targets read
  int samples = 0;                   /// the samples that read them
};

/// Every sample of `run`'s displacement columns whose ids name the observer's `targets` (its true
/// drift, where it was measured throughout), NaN for a target no column names; samples: the run's.
/// Throws DataError naming the run and saying `purpose` when no displacement column names a target.
DriftReadings drift_columns(const io::MeasuredRun& run, const std::vector<std::string>& targets,
                            const std::string& purpose);

/// The drift readings of `run` for the observer's `targets`: each displacement column whose id
/// names a target, at the first sample at or after each multiple of every_s (a probe cycle), NaN
/// elsewhere. Throws DataError naming the run when no displacement column names a target.
DriftReadings drift_readings(const io::MeasuredRun& run, const std::vector<std::string>& targets,
                             double every_s);

/// Throws DataError when the run has no speed column, when none of its sensors is located or a
/// named point of the twin (and none was chosen), a chosen sensor is not a column of the run or is
/// neither located nor named, a position lies outside the mesh (naming the run and sensor), or
/// drift readings are asked for and no displacement column names a target; what the observer
/// throws.
ObserveReport observe_run(const ObserveInput& input);

}  // namespace tt::studies
