// The one time loop of the thermal system: backward Euler or Crank–Nicolson on the case's time
// grid, a factor per (step, film state, scheme weight), the duty cycle's loads (films, sources,
// fluxes, heat that moves with the feed axis), and caller columns marched as linear responses
// with the same factors. Templated on the system's matrix type, so that the full model (sparse,
// CHOLMOD) and a reduced one (dense, Eigen::LLT; state z with T = V z) are stepped by one code.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <vector>

#include "core/case_spec.hpp"
#include "solvers/thermal.hpp"
#include "solvers/thermal_system.hpp"

namespace tt::solvers {

/// One step as a caller column sees it. A column's load b [W per unit] enters the response x as
/// (C + theta dt A) x1 = (C - (1 - theta) dt A) x0 + dt b, with A the step's K + sum h_c F_c:
/// b is the step's weighted load theta b(t1) + (1 - theta) b(t0) (b(t1) for backward Euler).
struct StepView {
  double t0 = 0, t1 = 0;                    /// step start and end [s]
  double speed = 0;                         /// spindle speed over the step [rpm]
  double theta = 1;                         /// 1: backward Euler; 0.5: Crank–Nicolson
  const Eigen::VectorXd* state0 = nullptr;  /// base state at t0
  const Eigen::VectorXd* state1 = nullptr;  /// base state at t1 (after the step)
  double dt() const { return t1 - t0; }
};

/// A fixed shape times a scalar law of (time, speed): b = shape law(t1, speed) for backward
/// Euler, shape (theta law(t1, speed) + (1 - theta) law(t0, speed)) for Crank–Nicolson.
struct ShapeColumn {
  Eigen::VectorXd shape;                              /// #states [W per unit]
  std::function<double(double t, double speed)> law;  /// [-]
};

/// A load that depends on the step and its base states (e.g. a film or material change times
/// the base temperature): returns the step's weighted load b, #states [W per unit].
using LoadCallback = std::function<Eigen::VectorXd(const StepView&)>;

/// Rows read from a state (the base, or each response column) at every recorded time:
/// y = [sparse x; dense x; change (x - x(0))], in that order; empty parts give no rows.
struct StateReadout {
  Eigen::SparseMatrix<double> sparse;  /// #a x #states, read from the state (e.g. sensors [K])
  Eigen::MatrixXd dense;               /// #b x #states, read from the state
  Eigen::MatrixXd change;              /// #c x #states, read from the change since t = 0
  Eigen::Index rows() const { return sparse.rows() + dense.rows() + change.rows(); }
};

/// What the stepper marches and records besides the base state.
struct StepperRequest {
  /// Times to record at (after t = 0, which is always recorded), ascending, within the duty
  /// cycle: values between step ends are interpolated linearly, as thermal_history's outputs.
  std::vector<double> record_times;
  bool record_states = true;               /// keep the base state at every recorded time
  StateReadout base_readout;               /// rows read from the base state
  std::vector<ShapeColumn> shape_columns;  /// responses, first in `responses`
  std::vector<LoadCallback> load_columns;  /// responses, after the shape columns
  StateReadout column_readout;             /// rows read from every response column
  SourceIteration sources;                 /// heat that grows with temperature within a step
};

/// The stepper's result.
struct SteppedHistory {
  std::vector<double> times;               /// t = 0, then the record times [s]
  Eigen::MatrixXd states;                  /// #states x #times (when record_states) [K | state]
  Eigen::MatrixXd readout;                 /// base_readout.rows() x #times
  std::vector<Eigen::MatrixXd> responses;  /// per column: column_readout.rows() x #times [per unit]
  Eigen::VectorXd final_state;             /// the base state at the end [K | state]
  double heat_in = 0;                      /// from the step loads over the steps [J]
  double lost = 0;                         /// through the films over the steps [J]
  ThermalTimings timings;                  /// assemble_s stays 0
  /// Most solves of one step with request.sources' iteration (1: no source moved the step).
  int source_iterations = 0;
};

/// Stiffnesses and factors kept between calls of step_thermal, so that runs of one system under
/// other duty cycles, sinks or loads (a generator's runs of one truth) factor each (step, film
/// coefficients, scheme weight) once for all of them. Keyed by the films' coefficients; a system
/// with other capacity, conduction or film matrices than the last one makes them forgotten first,
/// so any system may be stepped with them. One caller at a time.
template <class Matrix>
class KeptStepFactors {
 public:
  KeptStepFactors();
  ~KeptStepFactors();
  KeptStepFactors(const KeptStepFactors&) = delete;
  KeptStepFactors& operator=(const KeptStepFactors&) = delete;
  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// Steps `system` under `spec`'s duty cycle, feed axis, sinks and fluxes from the uniform
/// initial temperature (or from `checkpointing.resume`; checkpoints hold the base state and the
/// recorded states, and are refused with caller columns or readouts). Throws SolverError for
/// record times not ascending in (0, end], for columns or readouts whose size is not the system's,
/// for a resume state that does not fit, and when a factorisation fails. With `kept`, its
/// factors are used and the new ones added to it (KeptStepFactors).
template <class Matrix>
SteppedHistory step_thermal(const LinearThermalSystem<Matrix>& system, const core::CaseSpec& spec,
                            const StepperRequest& request, const Progress& progress = {},
                            const Checkpointing& checkpointing = {},
                            KeptStepFactors<Matrix>* kept = nullptr);

/// Load of every moving source averaged over the step [t0, t1]: sum_k moving[k] (fractions_k
/// power_k), #states [W] (sums to the sources' total power in the full space).
template <class Matrix>
Eigen::VectorXd moving_heat_load(const core::CaseSpec& spec,
                                 const LinearThermalSystem<Matrix>& system, double t0, double t1);

/// The load of one backward-Euler step [t0, t1] exactly as step_thermal forms it, in the system's
/// space: films at the step's speed with their sinks at t1, sources at the step's middle (the
/// temperature-dependent part from `state0`), fluxes, and the heat moving with the feed axis [W];
/// with the film coefficients over the step [W/(m^2 K)]. For the full-order residual of a reduced
/// step (the error indicator).
struct StepLoad {
  Eigen::VectorXd load;
  std::vector<double> film;
};
template <class Matrix>
StepLoad step_load(const LinearThermalSystem<Matrix>& system, const core::CaseSpec& spec, double t0,
                   double t1, const Eigen::VectorXd& state0);

/// One step of a reduced (dense) system as an affine map of its state, formed as step_thermal
/// forms the step: x1 = transition x0 + input, with (C + theta dt A) transition = C - (1 - theta)
/// dt A and (C + theta dt A) input = dt times the step's weighted load (the load's temperature-
/// dependent part from x0). For a filter that propagates a covariance with the runs' own
/// discretisation.
struct AffineStep {
  double t0 = 0, t1 = 0;     /// [s]
  double speed = 0;          /// spindle speed over the step [rpm]
  double theta = 1;          /// 1: backward Euler; 0.5: Crank–Nicolson
  std::vector<double> film;  /// h per convection entry over the step [W/(m^2 K)]
  const Eigen::MatrixXd* step_inverse = nullptr;  /// (C + theta dt A)^{-1}, r x r
  const Eigen::MatrixXd* transition = nullptr;    /// r x r
  Eigen::VectorXd input;                          /// r [state]
};

/// Steps a reduced system one step at a time under `spec`'s loads, with step_thermal's loads,
/// restarts and factors (one per step size, speed and scheme weight, kept for the next steps; at
/// most 64, then forgotten all at once, so that a stream's steps that never repeat do not grow
/// them without bound).
class ReducedStepper {
 public:
  ReducedStepper(const ReducedThermalSystem& system, const core::CaseSpec& spec);
  ~ReducedStepper();
  ReducedStepper(const ReducedStepper&) = delete;
  ReducedStepper& operator=(const ReducedStepper&) = delete;
  /// The step [t0, t1] from `state`; `prev_speed` is the speed of the step before (NaN for the
  /// first, which restarts Crank–Nicolson as a speed change does). The pointers stay valid until
  /// the next step. Throws SolverError when t1 <= t0 or the factorisation fails.
  AffineStep step(double t0, double t1, double prev_speed, const Eigen::VectorXd& state);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tt::solvers
