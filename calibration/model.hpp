// The declared model under a measured run's inputs, read where the run was measured: the run's
// speed column becomes the duty cycle, its sensors become interpolation weights, its displacement
// probes become adjoint influence vectors, and the response of every channel to the declared
// loads and to unit candidate effects comes out of one march per run: the thermal solver's own
// stepper (solvers::step_thermal) with the candidates as extra right-hand-side columns.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "io/measured_data.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/thermal_stepper.hpp"

namespace tt::calibration {

/// Where a run is read on the model: the channels that can be located, sensors first.
struct Readout {
  std::vector<std::string> ids;             /// channel ids: sensors, then probes
  std::vector<int> run_column;              /// per channel: column in the run's matrix
  int sensors = 0;                          /// channels [0, sensors) are temperatures
  Eigen::SparseMatrix<double> temperature;  /// #sensors x #nodes interpolation weights
  Eigen::MatrixXd displacement;             /// #probes x #nodes influence [m/K]
  double reference_k = 0;                   /// stress-free temperature [K]
  int channels() const { return static_cast<int>(ids.size()); }
};

/// Interpolation weights of a point over the nodes of the element that contains it (the nearest
/// element when the point lies just outside a faceted surface): (node, weight) pairs.
std::vector<std::pair<int, double>> point_weights(const mesh::TetMesh& mesh,
                                                  const Eigen::Vector3d& p);

/// Readout of `run`'s channels on `mesh`. Sensors without a position and probes without a point or
/// direction are left out. Throws DataError when nothing can be located.
Readout readout(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const io::MeasuredRun& run);

/// Same readout with the displacement rows for `spec` (e.g. another expansion coefficient) only.
Eigen::MatrixXd displacement_readout(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                     const io::MeasuredRun& run, const Readout& like);

/// The declared case under the run's inputs: its speed column as piecewise-constant segments
/// (a segment starts at the first sample that shows the new speed), its initial temperature when
/// it gives one, and its end at the last sample. Throws DataError without a speed column.
core::CaseSpec case_for_run(const core::CaseSpec& declared, const io::MeasuredRun& run);

/// The air temperature `run`'s ambient sensor reads: #samples [K], NaN missing; empty when the run
/// names no ambient sensor.
Eigen::VectorXd ambient_reading(const io::MeasuredRun& run);

/// Measured channels of `run` in the readout's order: #samples x #channels [K | m], NaN missing.
Eigen::MatrixXd measured_channels(const io::MeasuredRun& run, const Readout& r);

/// A load added to the declared model, whose channel response the march computes. `rhs` gets the
/// step (its ends, speed, scheme weight and the base states at both ends) and returns the step's
/// weighted load, #nodes [W per unit] (solvers::StepView says how it enters the response).
struct LoadColumn {
  std::string name;
  solvers::LoadCallback rhs;
};

/// A separable load: spatial vector b [W per unit] times a scalar law of (time, speed).
struct SeparableColumn {
  std::string name;
  Eigen::VectorXd shape;                              /// #nodes [W per unit parameter]
  std::function<double(double t, double speed)> law;  /// [-]
};

/// Channel histories at the run's sample times.
struct Responses {
  Eigen::MatrixXd base;                  /// #samples x #channels [K | m]
  std::vector<Eigen::MatrixXd> columns;  /// per load column: #samples x #channels per unit
  std::vector<Eigen::MatrixXd> extra;    /// per extra displacement readout, applied to the base
};

/// Marches `spec` with solvers::step_thermal (the case's scheme and time grid, the loads of
/// solvers::thermal_history) and the linear responses to `separable` then `loads` (in that order
/// in `columns`), all read through `r` and sampled at `times` by linear interpolation between the
/// step ends. `extra_displacement` are further #probes x #nodes readouts applied to the base field
/// (e.g. d/dalpha).
Responses march(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const Readout& r,
                const Eigen::VectorXd& times, const std::vector<SeparableColumn>& separable,
                const std::vector<LoadColumn>& loads,
                const std::vector<Eigen::MatrixXd>& extra_displacement = {});

/// Simulated channels of `spec` through the project's own pipeline (solvers::thermal_history and
/// the elastic influence vectors): what `thermotwin run` of that case gives, read at `times`.
Eigen::MatrixXd simulated_channels(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                   const Readout& r, const Eigen::VectorXd& times);

}  // namespace tt::calibration
