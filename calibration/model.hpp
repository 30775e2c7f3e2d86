// The declared model under a measured run's inputs, read where the run was measured: the run's
// speed column becomes the duty cycle, its sensors become interpolation weights, its displacement
// probes become adjoint influence vectors, and the response of every channel to the declared
// loads and to unit candidate effects comes out of one march per run: the thermal solver's own
// stepper (solvers::step_thermal) with the candidates as extra right-hand-side columns.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "core/case_spec.hpp"
#include "io/measured_data.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/reduction.hpp"
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
  /// Per probe: its point and unit direction, which the displacement rows were computed for.
  std::vector<Eigen::Vector3d> probe_point, probe_direction;
  /// Per material: the part of `displacement` that its elements' thermal strain makes [m/K], so
  /// that a relative change x of its expansion coefficient adds x times it (exact: the stiffness
  /// does not depend on the expansion).
  std::vector<Eigen::MatrixXd> expansion;
  int channels() const { return static_cast<int>(ids.size()); }
};

/// Interpolation weights of a point over the nodes of the element that contains it (the nearest
/// element when the point lies just outside a faceted surface): (node, weight) pairs.
std::vector<std::pair<int, double>> point_weights(const mesh::TetMesh& mesh,
                                                  const Eigen::Vector3d& p);

/// Temperature channels only: sensor `ids[k]` at `points[k]` (interpolated on `mesh`), no probes.
/// Throws DataError for ids and points that do not pair up or a point outside the mesh.
Readout temperature_readout(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                            const std::vector<std::string>& ids,
                            const std::vector<Eigen::Vector3d>& points);

/// Readout of `run`'s channels on `mesh`. Sensors without a position and probes without a point or
/// direction are left out. Throws DataError when nothing can be located.
Readout readout(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const io::MeasuredRun& run);

/// readout() of another run whose probes (points and directions) may be `like`'s: their
/// displacement rows are then taken from `like` instead of solved again.
Readout readout_like(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                     const io::MeasuredRun& run, const Readout& like);

/// The displacement rows of `like`'s probes for `spec` with its expansion coefficients changed
/// (the same mesh, stiffness and supports): like.displacement plus the relative change of each
/// material's coefficient times like.expansion.
Eigen::MatrixXd displacement_with_expansions(const Readout& like, const core::CaseSpec& declared,
                                             const core::CaseSpec& spec);

/// The declared case under the run's inputs: its speed column as piecewise-constant segments
/// (a segment starts at the first sample that shows the new speed), its initial temperature when
/// it gives one, and its end at the last sample. Throws DataError without a speed column.
core::CaseSpec case_for_run(const core::CaseSpec& declared, const io::MeasuredRun& run);

/// The air temperature `run`'s ambient sensor reads: #samples [K], NaN missing; empty when the run
/// names no ambient sensor.
Eigen::VectorXd ambient_reading(const io::MeasuredRun& run);

/// Measured channels of `run` in the readout's order: #samples x #channels [K | m], NaN missing.
Eigen::MatrixXd measured_channels(const io::MeasuredRun& run, const Readout& r);

/// The thermal system that calibration marches: the declared case's full system on its mesh and,
/// unless full order is asked for, a reduced model of it whose basis also holds the Krylov
/// vectors of the channels' rows (ReductionOptions::output_columns), so that the response at the
/// channels to any unit load (every candidate effect, unknown when the basis is built) is kept
/// (docs/reduced-order.md, "Calibration on the twin"). Loads are formed on the full system and
/// projected; loads that act on the base state act through the projected operators.
class MarchModel {
 public:
  /// Full order: every march steps the full system of `spec` on `mesh`.
  MarchModel(const mesh::TetMesh& mesh, const core::CaseSpec& spec);
  /// Reduced order: the basis from `spec`'s inputs and `r`'s channel rows (`options` for the rest;
  /// its output_columns are replaced by the rows).
  MarchModel(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const Readout& r,
             solvers::ReductionOptions options);

  /// The same basis with `other`'s operators on `mesh` (an augmented case meshed again: the
  /// same tets, other boundary groups): its full system assembled, projected on the basis when
  /// reduced. Throws SolverError when `mesh` has another number of nodes.
  MarchModel with_case(const mesh::TetMesh& mesh, const core::CaseSpec& other) const;

  const mesh::TetMesh& mesh() const { return *mesh_; }
  const solvers::FullThermalSystem& full() const { return *full_; }
  bool is_reduced() const { return reduced_ != nullptr; }
  /// The reduced model (basis and the declared case's projected system); null in full order.
  const solvers::ReducedModel* reduced() const { return reduced_.get(); }
  /// The reduced system marched (the declared case's, or the one `with_case` projected).
  const solvers::ReducedThermalSystem& reduced_system() const { return *system_; }
  /// V^T a V (reduced) [same units as a].
  Eigen::MatrixXd projected(const Eigen::SparseMatrix<double>& a) const;
  int order() const;  /// states marched: the reduced order, or the number of nodes

 private:
  const mesh::TetMesh* mesh_ = nullptr;
  std::shared_ptr<const solvers::FullThermalSystem> full_;
  std::shared_ptr<const solvers::ReducedModel> reduced_;
  std::shared_ptr<const solvers::ReducedThermalSystem> system_;
};

/// Loads a candidate effect adds to the declared model, per unit of its parameter; march forms
/// each on the system it steps (full, or reduced through the projected operators).
/// Heat exchanged with the air when the sinks of convection entries `entries` rise by a hat in
/// time (1 K at `knot_s`, 0 beyond +-`width_s`): hat(t) sum_e h_e(speed) a_e [W per K].
struct SinkHat {
  std::vector<int> entries;
  double knot_s = 0, width_s = 1;
};
/// A change of convection entry `entry`'s film coefficient, constant or growing with
/// (speed / ref_speed_rpm)^speed_exponent: -(F_e T - T_sink a_e) [W per W/(m^2 K)].
struct FilmChange {
  int entry = -1;
  bool follows_speed = false;
  double ref_speed_rpm = 1;
  double speed_exponent = 1;
};
/// Heat of source `source` growing with its mean temperature: q(t, speed) (s^T T - T0) s, s the
/// source's unit shape, T0 = reference_k [W per 1/K].
struct SourceGrowth {
  int source = -1;
  double reference_k = 0;
};
/// A change of conduction, -dK T, or of capacity, -dC (T1 - T0) / dt, per unit of a relative
/// change (dK, dC: the operator of the changed material, full order) [W per unit].
struct OperatorChange {
  enum class Operator { conduction, capacity } which = Operator::conduction;
  std::shared_ptr<const Eigen::SparseMatrix<double>> full;  /// #nodes x #nodes
  std::shared_ptr<const Eigen::MatrixXd> reduced;           /// V^T dA V, when marched reduced
};
/// Or any step load on the full system (full order only).
using LoadForm =
    std::variant<SinkHat, FilmChange, SourceGrowth, OperatorChange, solvers::LoadCallback>;

/// A load added to the declared model, whose channel response the march computes.
struct LoadColumn {
  std::string name;
  LoadForm form;
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

/// Marches `spec` with solvers::step_thermal (the case's scheme and time grid, its duty cycle's
/// loads) on `model`'s system (full or reduced) and the linear responses to `separable` then
/// `loads` (in that order in `columns`), all read through `r` and sampled at `times` by linear
/// interpolation between the step ends. `extra_displacement` are further #probes x #nodes
/// readouts applied to the base field (e.g. d/dalpha). `spec` must have `model`'s operators (the
/// declared case under a run's inputs: case_for_run). Throws SolverError for a callback load on a
/// reduced model.
Responses march(const MarchModel& model, const core::CaseSpec& spec, const Readout& r,
                const Eigen::VectorXd& times, const std::vector<SeparableColumn>& separable,
                const std::vector<LoadColumn>& loads,
                const std::vector<Eigen::MatrixXd>& extra_displacement = {});
/// The same in full order on `mesh`.
Responses march(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const Readout& r,
                const Eigen::VectorXd& times, const std::vector<SeparableColumn>& separable,
                const std::vector<LoadColumn>& loads,
                const std::vector<Eigen::MatrixXd>& extra_displacement = {});

/// Simulated channels of `spec` through the project's own pipeline (solvers::thermal_history and
/// the elastic influence vectors): what `thermotwin run` of that case gives, read at `times`.
Eigen::MatrixXd simulated_channels(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                   const Readout& r, const Eigen::VectorXd& times);

}  // namespace tt::calibration
