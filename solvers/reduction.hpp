// A reduced-order thermal model: the full system projected on a basis V (#nodes x r) that spans
// the response of every input (sources, sink temperatures, surface fluxes, heat moving with the
// feed axis) at several Laplace shifts and film states, so that a duty cycle runs on r states.
//
// Method (docs/reduced-order.md says why, with the measured alternatives): block rational Krylov
// (moment matching). For each film state h (the film coefficients at the speeds asked for) and
// each shift s, V takes X = (K(h) + s C)^{-1} B and (K(h) + s C)^{-1} C X, B the input columns;
// s = 0 is the steady state.
// V is orthonormal in the capacity inner product (V^T C V = I) and holds the uniform field, so
// the model starts exactly from the uniform initial temperature. The Galerkin projection keeps
// every operator separately (capacity, conduction, each film), so a film that follows the speed
// stays exact in the reduced model; the reduced K(h) = V^T K V + sum h_c V^T F_c V is symmetric
// positive semi-definite for every h >= 0 and the reduced capacity is I: the reduced backward-
// Euler and Crank-Nicolson steps are stable by construction (spectral radius <= 1).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "core/case_spec.hpp"
#include "solvers/thermal_system.hpp"

namespace tt::solvers {

/// Default tolerance of the error indicator [K]: half the accuracy the reduced model is built for
/// (0.01 K), since the indicator is an estimate that has read down to 0.85 of the true error.
constexpr double kReducedToleranceK = 0.005;

struct ReductionOptions {
  /// Laplace shifts [1/s]; empty: 0 (steady state, when some film removes heat) and 5 shifts
  /// log-spaced from 1/(10 h) to 1/(the case's time step).
  std::vector<double> shifts_per_s;
  /// Spindle speeds whose film coefficients are sampled [rpm]; empty: 0 and the duty cycle's
  /// highest speed. States with the same coefficients are sampled once.
  std::vector<double> speeds_rpm;
  /// A second moment (K + sC)^{-1} C X per shift as well (20 to 30 times more accurate on SB-1
  /// coarse for 1.7 times the states, no more factors: docs/reduced-order.md).
  bool second_moment = true;
  /// With second_moment: whether the moving sources' slices take it too. Off (the default), the
  /// second moment is taken of the other inputs and the output columns only: the slices are most
  /// of the columns, and on GM-1 coarse their second moment costs 1009 states against 753 for
  /// errors that stay well inside the limits (docs/reduced-order.md).
  bool moving_second_moment = false;
  /// A new column is dropped when orthogonalisation leaves less than this fraction of its
  /// capacity norm [-].
  double deflation_tolerance = 1e-9;
  /// 0: keep every column that is not dependent. > 0: per block (one film state, shift and
  /// moment), with each column scaled to unit C-norm, keep only the principal directions whose
  /// singular value exceeds this [-] (fewer states where many inputs act alike, as the slices of
  /// a moving source do).
  double compression_tolerance = 0;
  /// Spacing of the moving source's input columns along the axis, as a fraction of its window
  /// [-]: the width of box slices, the largest distance between hats' centres. 0.375 with hats:
  /// on GM-1 coarse, error indicator 2.2e-3 K and 1.1e-3 K at every node at order 579, where box
  /// slices of a quarter window read 2.4e-3 and 1.3e-3 K at order 753; hats at half a window
  /// read 3.5e-3 K (order 486), boxes of half a window 0.011 K, above the 0.005 K tolerance
  /// (docs/reduced-order.md).
  double moving_slice_fraction = 0.375;
  /// How a moving source's pieces are weighted into its input columns. box: slices of width
  /// moving_slice_fraction x window, each piece in one slice (piecewise-constant power densities
  /// along the axis). hat (the default): piecewise-linear hats whose centres are at most that far
  /// apart, a piece shared between the two hats around it by its position (their sum is every
  /// piece's volume: a partition of unity). A window's edge falls inside a slice or a hat; hats
  /// also hold the linear part of the power density there, so the error the edge leaves grows
  /// more slowly with the spacing.
  enum class SliceShape { box, hat };
  SliceShape moving_slice_shape = SliceShape::hat;
  /// Output rows transposed, #nodes x #outputs (e.g. sensors' interpolation rows, probes'
  /// influence vectors), whose Krylov vectors (K(h) + s C)^{-1} L^T join the basis at every film
  /// state and shift. The system is symmetric, so a Galerkin basis that holds them matches the
  /// moments of L (K(h) + s C)^{-1} b for EVERY load b, not only the case's inputs: the responses
  /// at those outputs to loads unknown when the basis is built (calibration's candidate effects)
  /// are kept. Empty: the inputs' Krylov spaces only.
  Eigen::MatrixXd output_columns;
};

/// What the basis was built from, for the run's summary.
struct ReductionStats {
  std::vector<double> shifts_per_s;              /// shifts used [1/s]
  std::vector<std::vector<double>> film_states;  /// per state: h per convection entry [W/(m^2 K)]
  int input_columns = 0;                         /// columns of B
  int output_columns = 0;                        /// output rows whose Krylov vectors were added
  int candidate_columns = 0;                     /// columns offered to the basis
  int deflated_columns = 0;                      /// of those, dropped as dependent
  int factorizations = 0;
  double build_s = 0;          /// wall time of basis and projection [s]
  double solve_s = 0;          /// of which factors and solves [s]
  double orthogonalise_s = 0;  /// of which orthonormalisation against the basis [s]
  double projection_s = 0;     /// of which the Galerkin projection [s]
};

struct ReducedModel {
  ReducedThermalSystem system;  /// T = V z; capacity = I (V^T C V to rounding, not formed)
  Eigen::MatrixXd basis;        /// V: #nodes x r, V^T C V = I
  ReductionStats stats;
  int states() const { return static_cast<int>(basis.cols()); }
};

/// The input columns of the full system, one per independent load shape: the uniform field, each
/// fixed source's shape, each film's area (its sink temperature's input), each flux's area, and
/// each moving source's pieces grouped into slices along the axis (unit power by volume):
/// #nodes x #inputs.
Eigen::MatrixXd input_columns(const FullThermalSystem& full, const core::CaseSpec& spec,
                              const ReductionOptions& options = {});

/// The basis V: #nodes x r, V^T C V = I, uniform field first. Throws SolverError when a shifted
/// matrix cannot be factored.
Eigen::MatrixXd reduction_basis(const FullThermalSystem& full, const core::CaseSpec& spec,
                                const ReductionOptions& options = {},
                                ReductionStats* stats = nullptr);

/// The Galerkin projection of every operator and vector on `basis` (moving pieces kept).
ReducedThermalSystem projected_system(const FullThermalSystem& full, const Eigen::MatrixXd& basis);

/// Basis and projection in one call; the reduced capacity is I, which the basis's Gram-Schmidt
/// makes V^T C V to rounding.
ReducedModel reduced_model(const FullThermalSystem& full, const core::CaseSpec& spec,
                           const ReductionOptions& options = {});

/// Output rows on the reduced state, rows * V: #rows x r (sensor interpolation rows, influence
/// vectors). Throws SolverError when rows has not one column per node.
Eigen::MatrixXd project_rows(const ReducedModel& model, const Eigen::SparseMatrix<double>& rows);
Eigen::MatrixXd project_rows(const ReducedModel& model, const Eigen::MatrixXd& rows);

/// Nodal temperatures of reduced states, V z: #nodes x #states columns [K].
Eigen::MatrixXd reconstructed(const ReducedModel& model, const Eigen::MatrixXd& states);

/// Throws SolverError, naming what differs, when `spec` asks for something the reduced model
/// cannot answer exactly: another number of convection entries, sources, fluxes or moving
/// sources than it was built with (another case), or the full system it is checked against has
/// another number of nodes (another mesh).
void check_reducible(const ReducedModel& model, const FullThermalSystem& full,
                     const core::CaseSpec& spec);

/// One time step of a reduced run, as the error indicator samples it.
struct ReducedStep {
  double dt = 0;              /// step [s]
  double theta = 1;           /// 1 backward Euler, 0.5 Crank-Nicolson
  std::vector<double> film;   /// h per convection entry over the step [W/(m^2 K)]
  Eigen::VectorXd state_old;  /// z_n
  Eigen::VectorXd state_new;  /// z_{n+1}
  Eigen::VectorXd load;       /// full-order load of the step, theta f_{n+1} + (1-theta) f_n [W]
  double horizon = 0;         /// time since the loads last changed (duty-cycle, feed-axis or
                              /// sink switch) at the step's end [s]
};

/// Estimated full-order error of a reduced step's end state [K]: the step's full-order residual
/// r = C (T_{n+1} - T_n)/dt + K(h) (theta T_{n+1} + (1 - theta) T_n) - f, T = V z (zero in the
/// span of V, by Galerkin), turned into temperature by the full system over the horizon,
/// e = (K(h) + C/tau)^{-1} r with tau = max(dt, horizon) rounded to a power of sqrt(2): the
/// one-step correction just after a switch, and the error that a residual persisting since the
/// switch has built up later. One sparse factor per (film state, tau). Returns max |e| over the
/// nodes. An estimate, not a bound: docs/reduced-order.md gives its measured ratio to the true
/// error. Sample steps that end at output times: just after a switch, the reduced model's error
/// between output times can be larger and decays within a minute.
double step_error_estimate(const FullThermalSystem& full, const Eigen::MatrixXd& basis,
                           const ReducedStep& step);

struct ErrorIndicator {
  std::vector<double> samples_k;  /// per sampled step [K]
  double max_k = 0;               /// over the samples [K]
  double tolerance_k = kReducedToleranceK;
  bool above_tolerance() const { return max_k > tolerance_k; }
};

/// The indicator over sampled steps (steps that end at output times: all, or the first after each
/// switch, the last before each and the last): samples with the same film state and rounded
/// horizon share one factor and one block solve.
ErrorIndicator error_indicator(const FullThermalSystem& full, const ReducedModel& model,
                               const std::vector<ReducedStep>& steps,
                               double tolerance_k = kReducedToleranceK);

}  // namespace tt::solvers
