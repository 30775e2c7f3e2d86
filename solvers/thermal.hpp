// Transient heat conduction: the system assembled once from the mesh and the case
// (solvers/thermal_system.hpp), then a time history under the duty cycle from the one stepper
// (solvers/thermal_stepper.hpp: a CHOLMOD factor per distinct (step, speed, scheme weight) and a
// back-substitution per step).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <vector>

#include "core/case_spec.hpp"
#include "core/units.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/feed_axis.hpp"
#include "solvers/thermal_system.hpp"

namespace tt::solvers {

/// Heat in, stored and lost, each computed on its own path [J].
struct EnergyBalance {
  double heat_in = 0;      /// from the sources' laws over the steps
  double heat_in_law = 0;  /// from the laws over the duty cycle alone
  double stored = 0;       /// quadrature of rho c (T - T0) over the mesh at the end
  double lost = 0;         /// quadrature of h (T - T_sink) over the surfaces, over time
  double closure() const { return (heat_in - stored - lost) / heat_in; }
};

struct ThermalTimings {
  double assemble_s = 0, factor_s = 0, solve_s = 0;
  int steps = 0, factorizations = 0;
  double factor_entries = 0;  /// entries of the largest Cholesky factor
};

struct ThermalHistory {
  std::vector<double> times;    /// output times, t = 0 first [s]
  Eigen::MatrixXd temperature;  /// #nodes x #times [K]
  EnergyBalance energy;
  ThermalTimings timings;
};

/// Progress: (simulated time [s], end time [s]).
using Progress = std::function<void(double, double)>;

/// The time loop's whole state after `steps` steps: enough to continue and end with the same
/// numbers as a run that was never interrupted.
struct ThermalCheckpoint {
  int steps = 0;                 /// time steps done (index of the next step in the time grid)
  double time = 0;               /// simulated time reached [s]
  double speed = 0;              /// spindle speed of the last step [rpm] (CN restarts on a change)
  Eigen::VectorXd temperature;   /// #nodes [K] at `time`
  Eigen::MatrixXd outputs;       /// #nodes x #output times written so far [K], t = 0 first
  double heat_in = 0, lost = 0;  /// energy accumulators so far [J]
};

/// Checkpoints during the time loop: `save` gets the state after a step when `interval_s` of wall
/// time have passed since the start or the last save (0: after every step; no save after the
/// last step). `resume`, when given, is a state saved earlier for the same mesh and case.
struct Checkpointing {
  double interval_s = 600;
  std::function<void(const ThermalCheckpoint&)> save;
  const ThermalCheckpoint* resume = nullptr;
};

/// Heat that grows with temperature (a source's temperature_coefficient) within one step: by
/// default (tolerance 0) each source's power is taken at its mean temperature at the step's
/// start, i.e. lagged by one step. With a tolerance, the step is solved again with the powers at
/// the step's end (and, for Crank–Nicolson, at its start for the start's half) until no source's
/// mean temperature moves by more than `tolerance_K` between two solves (a fixed point on the
/// step's factor: one back-substitution per iteration); more than `max_iterations` solves is a
/// SolverError.
struct SourceIteration {
  double tolerance_K = 0;  /// 0: lagged by one step
  int max_iterations = 30;
};

template <class Matrix>
class KeptStepFactors;

/// Integrates the transient from the uniform initial temperature (or from `checkpointing.resume`)
/// to the duty cycle's end; heat that grows with temperature is lagged by one step unless
/// `sources` asks for it to be iterated within each step (SourceIteration). With `kept`, the
/// factors it holds are used and the new ones added to it (several runs of one system). Throws
/// SolverError when the resume state does not fit the mesh and the case's time grid.
ThermalHistory thermal_history(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                               const FullThermalSystem& system, const Progress& progress = {},
                               const Checkpointing& checkpointing = {},
                               const SourceIteration& sources = {},
                               KeptStepFactors<Eigen::SparseMatrix<double>>* kept = nullptr);

/// Heat stored in the mesh at `temperature` relative to the uniform initial temperature [J]:
/// quadrature of rho c (T - T0) over the elements.
double stored_heat(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                   const Eigen::VectorXd& temperature);

/// Heat delivered from the laws over the duty cycle, the sources' and the surface fluxes' [J]: the
/// energy balance's independent path (no solver).
double heat_in_law(const core::CaseSpec& spec, const FullThermalSystem& system);

/// The history at some nodes, as a sensor there would record it: #times x nodes.size() [K].
/// Throws SolverError for a node the history does not have.
Eigen::MatrixXd nodal_history(const ThermalHistory& history, const std::vector<int>& nodes);

/// Element coordinates gathered from the mesh: 3 x nodes-per-element [m].
Eigen::Matrix<double, 3, Eigen::Dynamic> element_coordinates(const mesh::TetMesh& mesh, int tet);

}  // namespace tt::solvers
