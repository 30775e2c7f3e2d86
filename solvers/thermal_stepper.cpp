#include "solvers/thermal_stepper.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <type_traits>

#include "core/errors.hpp"
#include "core/limits.hpp"
#include "core/timing.hpp"
#include "solvers/cholmod/cholmod_factor.hpp"
#include "solvers/feed_axis.hpp"
#include "solvers/loads.hpp"

namespace tt::solvers {

using core::seconds_since;
namespace {

using Clock = std::chrono::steady_clock;
using Sparse = Eigen::SparseMatrix<double>;
using Dense = Eigen::MatrixXd;

/// The solve of C + theta dt A: CHOLMOD for the sparse system, a dense Cholesky for a reduced one.
template <class Matrix>
class StepFactor;

template <>
class StepFactor<Sparse> {
 public:
  StepFactor(const Sparse& a, const std::string& what) : f_(a, what) {}
  void solve_in_place(Eigen::VectorXd& x) const { f_.solve_in_place(x); }
  Dense solve(const Dense& b) const { return f_.solve(b); }
  double entries() const { return f_.factor_entries(); }

 private:
  cholmod::Factor f_;
};

/// A reduced system's step matrix is small and dense: its inverse, formed once from the Cholesky
/// factor, makes each step one matrix-vector product instead of two triangular solves.
template <>
class StepFactor<Dense> {
 public:
  StepFactor(const Dense& a, const std::string& what) {
    const Eigen::LLT<Dense> llt(a);
    if (llt.info() != Eigen::Success)
      throw core::SolverError(what +
                              ": the dense Cholesky factorisation failed (the matrix is "
                              "not positive definite). Hint: check the reduced basis");
    inverse_ = llt.solve(Dense::Identity(a.rows(), a.cols()));
  }
  void solve_in_place(Eigen::VectorXd& x) const { x = inverse_ * x; }
  Dense solve(const Dense& b) const { return inverse_ * b; }
  double entries() const { return static_cast<double>(inverse_.size()); }
  const Dense& inverse() const { return inverse_; }

 private:
  Dense inverse_;
};

/// The loads at one instant: matrix key (speed), film coefficients, sinks, source powers.
struct LoadState {
  double speed = 0;
  std::vector<double> h, sink_k, power;
};

template <class Matrix>
LoadState load_state(const core::CaseSpec& spec, const LinearThermalSystem<Matrix>& sys,
                     double t_load, double t_sink, const Eigen::VectorXd& state, double t0_k) {
  LoadState s;
  s.speed = speed_at(spec.duty_cycle, t_load);
  for (const auto& c : spec.thermal.convection) {
    s.h.push_back(film_coefficient(c, s.speed));
    s.sink_k.push_back(table_value(c.sink, t_sink) + core::kCelsiusOffset);
  }
  const double feed = feed_speed_at(spec.feed_axis, t_load);
  for (size_t i = 0; i < spec.thermal.sources.size(); ++i) {
    const auto& src = spec.thermal.sources[i];
    // Moving sources enter through moving_heat_load, not through source_shape.
    double p = src.window > 0 ? 0.0 : source_power(src, s.speed, feed);
    if (src.temperature_coefficient != 0)
      p *= 1 + src.temperature_coefficient * (sys.source_shape[i].dot(state) - t0_k);
    s.power.push_back(p);
  }
  return s;
}

/// Scale of a surface flux at spindle speed n [-].
double flux_scale(const core::SurfaceFlux& fl, double speed) {
  return fl.follows_speed ? (speed > 0 ? speed / fl.ref_speed_rpm : 0.0) : 1.0;
}

template <class Matrix>
Eigen::VectorXd load_vector(const core::CaseSpec& spec, const LinearThermalSystem<Matrix>& sys,
                            const LoadState& s) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(sys.states());
  for (size_t c = 0; c < s.h.size(); ++c) f += (s.h[c] * s.sink_k[c]) * sys.film_area[c];
  for (size_t i = 0; i < s.power.size(); ++i) f += s.power[i] * sys.source_shape[i];
  for (size_t i = 0; i < spec.thermal.fluxes.size(); ++i) {
    const auto& fl = spec.thermal.fluxes[i];
    f += fl.flux * flux_scale(fl, s.speed) * sys.flux_area[i];
  }
  return f;
}

/// What one step [t_prev, t] loads, as the loop forms it: the loads at the step's end, the scheme
/// weight (Crank–Nicolson restarts with one backward-Euler step after every load discontinuity:
/// when the speed differs from `prev_speed`, NaN before the first step), the heat moving with the
/// feed axis (averaged over the step, the same for both ends of CN) and the step's load times dt,
/// so that (C + theta dt A) x1 = (C - (1 - theta) dt A) x0 + load.
struct StepPlan {
  LoadState s_new, s_old;  /// s_old: the loads at t_prev (Crank–Nicolson only)
  double theta = 1;
  Eigen::VectorXd f_moving, load;
};

template <class Matrix>
StepPlan step_plan(const core::CaseSpec& spec, const LinearThermalSystem<Matrix>& sys,
                   double t_prev, double t, double prev_speed, const Eigen::VectorXd& temp,
                   double t0_k) {
  const double dt = t - t_prev, mid = 0.5 * (t_prev + t);
  StepPlan p;
  p.s_new = load_state(spec, sys, mid, t, temp, t0_k);
  const bool cn =
      spec.thermal.scheme == core::TimeScheme::crank_nicolson && p.s_new.speed == prev_speed;
  p.theta = cn ? 0.5 : 1.0;
  p.f_moving = moving_heat_load(spec, sys, t_prev, t);
  const Eigen::VectorXd f_new = load_vector(spec, sys, p.s_new) + p.f_moving;
  if (cn) {
    p.s_old = load_state(spec, sys, mid, t_prev, temp, t0_k);
    p.load = (0.5 * dt) * (load_vector(spec, sys, p.s_old) + p.f_moving + f_new);
  } else {
    p.load = dt * f_new;
  }
  return p;
}

/// The step solved again with each temperature-dependent source's power at the step's end state
/// (SourceIteration): a fixed point on the step's factor, since only the load moves. `rhs` is the
/// right-hand side `next` was solved from; `p.s_new.power` ends at the powers of the last solve.
/// Returns the number of solves (1 when no source depends on temperature).
template <class Matrix>
int iterate_sources(const core::CaseSpec& spec, const LinearThermalSystem<Matrix>& sys,
                    const SourceIteration& it, const StepFactor<Matrix>& factor, double t_prev,
                    double t, double t0_k, Eigen::VectorXd rhs, StepPlan& p,
                    Eigen::VectorXd& next) {
  const double dt = t - t_prev, weight = p.theta * dt;
  const auto& sources = spec.thermal.sources;
  const bool any = std::any_of(sources.begin(), sources.end(), [](const core::HeatSource& s) {
    return s.temperature_coefficient != 0;
  });
  if (!any) return 1;
  for (int solves = 1;; ++solves) {
    const LoadState s = load_state(spec, sys, 0.5 * (t_prev + t), t, next, t0_k);
    Eigen::VectorXd previous = next;
    for (size_t k = 0; k < s.power.size(); ++k)
      rhs += (weight * (s.power[k] - p.s_new.power[k])) * sys.source_shape[k];
    p.s_new.power = s.power;
    next = rhs;
    factor.solve_in_place(next);
    double moved = 0;
    for (size_t k = 0; k < sources.size(); ++k)
      if (sources[k].temperature_coefficient != 0)
        moved = std::max(moved, std::abs(sys.source_shape[k].dot(next - previous)));
    if (moved <= it.tolerance_K) return solves + 1;
    if (solves + 1 >= it.max_iterations) {
      std::ostringstream o;
      o << spec.source.string() << ": the heat that grows with temperature did not settle within "
        << it.max_iterations << " solves of the step ending at t = " << t
        << " s (a source's mean temperature still moved by " << moved << " K, tolerance "
        << it.tolerance_K
        << " K). Hint: a temperature_coefficient_per_K times the source's power beyond what the "
           "films and the step can carry away makes the heat run away; check the coefficient or "
           "shorten thermal.step_s";
      throw core::SolverError(o.str());
    }
  }
}

/// Heat rate leaving through every film [W]: h (int T dA - T_sink int dA).
template <class Matrix>
double convected_rate(const LinearThermalSystem<Matrix>& sys, const std::vector<double>& area,
                      const Eigen::VectorXd& state, const LoadState& s) {
  double rate = 0;
  for (size_t c = 0; c < s.h.size(); ++c)
    rate += s.h[c] * (sys.film_area[c].dot(state) - s.sink_k[c] * area[c]);
  return rate;
}

/// Checks that a saved state belongs to this system and time grid before the loop trusts it.
void check_resume(const ThermalCheckpoint& c, Eigen::Index states, const std::vector<double>& grid,
                  size_t times) {
  const auto fail = [](const std::string& what) {
    throw core::SolverError("checkpoint does not fit this run: " + what +
                            "; remove the checkpoint or run without --resume");
  };
  if (c.temperature.size() != states || c.outputs.rows() != states)
    fail("it has " + std::to_string(c.temperature.size()) + " nodes, the mesh " +
         std::to_string(states));
  if (c.steps < 1 || static_cast<size_t>(c.steps) >= grid.size() || grid[c.steps - 1] != c.time)
    fail("step " + std::to_string(c.steps) + " at t = " + std::to_string(c.time) +
         " s is not an inner step of the time grid (" + std::to_string(grid.size()) + " steps)");
  if (c.outputs.cols() < 1 || static_cast<size_t>(c.outputs.cols()) > times)
    fail(std::to_string(c.outputs.cols()) + " output columns, at most " + std::to_string(times) +
         " expected");
}

/// The readout of one state (the base) [rows].
Eigen::VectorXd read_state(const StateReadout& r, const Eigen::VectorXd& x,
                           const Eigen::VectorXd& x_start) {
  Eigen::VectorXd y(r.rows());
  const Eigen::Index a = r.sparse.rows(), b = r.dense.rows(), c = r.change.rows();
  if (a) y.head(a) = r.sparse * x;
  if (b) y.segment(a, b) = r.dense * x;
  if (c) y.tail(c) = r.change * (x - x_start);
  return y;
}

/// The readout of a block of response columns (which start from zero): rows x #columns.
Dense read_block(const StateReadout& r, const Dense& x) {
  Dense y(r.rows(), x.cols());
  const Eigen::Index a = r.sparse.rows(), b = r.dense.rows(), c = r.change.rows();
  if (a) y.topRows(a) = r.sparse * x;
  // Coefficient-wise products: a few rows do not pay for a blocked, OpenMP-parallel GEMM, whose
  // threads wait on each other every step when the cores are shared.
  if (b) y.middleRows(a, b) = r.dense.lazyProduct(x);
  if (c) y.bottomRows(c) = r.change.lazyProduct(x);
  return y;
}

template <class Matrix>
void check_request(const LinearThermalSystem<Matrix>& sys, const StepperRequest& q, double end) {
  const Eigen::Index n = sys.states();
  const auto fits = [n](const StateReadout& r) {
    return (r.sparse.rows() == 0 || r.sparse.cols() == n) &&
           (r.dense.rows() == 0 || r.dense.cols() == n) &&
           (r.change.rows() == 0 || r.change.cols() == n);
  };
  if (!fits(q.base_readout) || !fits(q.column_readout))
    throw core::SolverError("thermal stepper: a readout's rows do not have " + std::to_string(n) +
                            " columns (the system's states)");
  for (size_t k = 0; k < q.record_times.size(); ++k)
    if (!(q.record_times[k] > (k ? q.record_times[k - 1] : 0.0)) ||
        q.record_times[k] > end * (1 + 1e-9))
      throw core::SolverError("thermal stepper: record time " + std::to_string(q.record_times[k]) +
                              " s is not after the one before it or beyond the end (" +
                              std::to_string(end) + " s): expected ascending times in (0, end]");
  if (!(q.sources.tolerance_K >= 0) || q.sources.max_iterations < 2)
    throw core::SolverError(
        "thermal stepper: the sources' iteration needs a tolerance >= 0 K (got " +
        std::to_string(q.sources.tolerance_K) + ") and at least 2 solves (got " +
        std::to_string(q.sources.max_iterations) + ")");
  for (const auto& c : q.shape_columns)
    if (c.shape.size() != n || !c.law)
      throw core::SolverError("thermal stepper: a shape column has " +
                              std::to_string(c.shape.size()) + " entries (expected " +
                              std::to_string(n) + ") or no law");
}

/// Stiffness K + sum h_c F_c per film state and factors of C + theta dt A per (step, film state,
/// theta), built on first use and keyed by the films' coefficients (not the speed: speeds with
/// the same films share them, and a case with other film laws on the same system may use them);
/// factorisations are counted in the timings it is given.
template <class Matrix>
class StepOperators {
 public:
  StepOperators(const LinearThermalSystem<Matrix>& sys, ThermalTimings& timings)
      : sys_(&sys), timings_(&timings) {}

  /// The same operators on `sys` (a system with the same matrices), counted in `timings`.
  void rebind(const LinearThermalSystem<Matrix>& sys, ThermalTimings& timings) {
    sys_ = &sys;
    timings_ = &timings;
  }

  const Matrix& stiffness(const LoadState& s) {
    auto it = stiffness_.find(s.h);
    if (it != stiffness_.end()) return it->second;
    Matrix kk = sys_->conduction;
    for (size_t c = 0; c < s.h.size(); ++c) kk += s.h[c] * sys_->film[c];
    if constexpr (std::is_same_v<Matrix, Sparse>) kk.makeCompressed();
    return stiffness_.emplace(s.h, std::move(kk)).first->second;
  }

  const StepFactor<Matrix>& factor(double dt, double theta, const LoadState& s) {
    const auto key = std::make_tuple(std::round(dt * 1e9) / 1e9, theta, s.h);
    auto it = factors_.find(key);
    if (it != factors_.end()) return *it->second;
    const auto t_f = Clock::now();
    Matrix a = sys_->capacity + (theta * dt) * stiffness(s);
    if constexpr (std::is_same_v<Matrix, Sparse>) a.makeCompressed();
    std::ostringstream what;
    what << "thermal system (dt = " << dt << " s, speed = " << s.speed << " rpm)";
    auto f = std::make_unique<StepFactor<Matrix>>(a, what.str());
    timings_->factor_s += seconds_since(t_f);
    timings_->factorizations += 1;
    timings_->factor_entries = std::max(timings_->factor_entries, f->entries());
    return *factors_.emplace(key, std::move(f)).first->second;
  }

  /// Forgets every stiffness and factor (references to them end here).
  void forget() {
    factors_.clear();
    stiffness_.clear();
  }

 private:
  const LinearThermalSystem<Matrix>* sys_;
  ThermalTimings* timings_;
  std::map<std::vector<double>, Matrix> stiffness_;
  std::map<std::tuple<double, double, std::vector<double>>, std::unique_ptr<StepFactor<Matrix>>>
      factors_;
};

/// Whether `a` and `b` hold the same entries (sparse: the same compressed pattern and values).
bool same_matrix(const Sparse& a, const Sparse& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols() || a.nonZeros() != b.nonZeros() ||
      !a.isCompressed() || !b.isCompressed())
    return false;
  const Eigen::Index nz = a.nonZeros(), outer = a.outerSize() + 1;
  return std::equal(a.outerIndexPtr(), a.outerIndexPtr() + outer, b.outerIndexPtr()) &&
         std::equal(a.innerIndexPtr(), a.innerIndexPtr() + nz, b.innerIndexPtr()) &&
         std::equal(a.valuePtr(), a.valuePtr() + nz, b.valuePtr());
}
bool same_matrix(const Dense& a, const Dense& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && a == b;
}

/// Whether `a` and `b` step alike: the same capacity, conduction and films.
template <class Matrix>
bool same_operators(const LinearThermalSystem<Matrix>& a, const LinearThermalSystem<Matrix>& b) {
  return a.film.size() == b.film.size() && same_matrix(a.capacity, b.capacity) &&
         same_matrix(a.conduction, b.conduction) &&
         std::equal(a.film.begin(), a.film.end(), b.film.begin(),
                    [](const Matrix& x, const Matrix& y) { return same_matrix(x, y); });
}

/// The caller columns' responses after the step `view` from `x` (#states x #columns), with the
/// base's stiffness and factor: (C + theta dt A) x1 = (C - (1 - theta) dt A) x + dt b.
template <class Matrix>
Dense stepped_responses(const LinearThermalSystem<Matrix>& sys, const StepperRequest& q,
                        const StepView& view, const Matrix& kk, const StepFactor<Matrix>& factor,
                        const Dense& x) {
  const double dt = view.dt(), t = view.t1, speed = view.speed;
  const bool cn = view.theta != 1;
  Dense b = sys.capacity * x;
  if (cn) b -= (0.5 * dt) * (kk * x);
  const auto ns = static_cast<Eigen::Index>(q.shape_columns.size());
  for (Eigen::Index j = 0; j < ns; ++j) {
    const auto& col = q.shape_columns[static_cast<size_t>(j)];
    const double law = cn ? 0.5 * (col.law(t, speed) + col.law(view.t0, speed)) : col.law(t, speed);
    b.col(j) += (dt * law) * col.shape;
  }
  for (size_t j = 0; j < q.load_columns.size(); ++j)
    b.col(ns + static_cast<Eigen::Index>(j)) += dt * q.load_columns[j](view);
  return factor.solve(b);
}

/// Why a step's temperatures are not finite: the step, a state entry, and the loads that entered
/// it (the case's numbers that can overflow: heat source powers, film coefficients, sinks).
core::SolverError non_finite_temperature(const core::CaseSpec& spec, const LoadState& s,
                                         const Eigen::VectorXd& temperature, std::size_t step,
                                         double t) {
  Eigen::Index node = 0;
  while (node + 1 < temperature.size() && std::isfinite(temperature[node])) ++node;
  std::ostringstream o;
  o << spec.source.string() << ": the temperature is not finite (" << temperature[node]
    << " at node " << node << ") after time step " << step + 1 << ", t = " << t
    << " s; nothing is written. The step's loads:";
  for (std::size_t k = 0; k < s.power.size(); ++k)
    o << " heat source '" << spec.thermal.sources[k].name << "' " << s.power[k] << " W;";
  for (std::size_t k = 0; k < s.h.size(); ++k)
    o << " convection[" << k << "] h = " << s.h[k] << " W/(m^2 K), sink "
      << s.sink_k[k] - core::kCelsiusOffset << " degC;";
  o << " Hint: a power, flux or coefficient far beyond a machine's (thermal.heat_sources "
       "power_ref_W, surface_flux flux_W_m2, h_W_m2K, the material values) overflows a double.";
  return core::SolverError(o.str());
}

/// The recorded states (and the displacement history after them, three values per node) are
/// kept whole in memory: refuse before allocating beyond core::limits::kHistoryBytes.
void require_history_fits(const core::CaseSpec& spec, Eigen::Index states, std::size_t times) {
  const double per_state = spec.mechanical.enabled ? 4 : 1;
  const double bytes =
      per_state * sizeof(double) * static_cast<double>(states) * static_cast<double>(times);
  if (bytes <= static_cast<double>(core::limits::kHistoryBytes)) return;
  throw core::SolverError(
      spec.source.string() +
      ": thermal.output_interval_s = " + std::to_string(spec.thermal.output_interval) +
      " s gives " + std::to_string(times) + " output times of " + std::to_string(states) +
      " nodes: the histories would take " + std::to_string(bytes / 1e9) +
      " GB, more than the limit of " + core::limits::bytes_text(core::limits::kHistoryBytes) +
      " (core/limits.hpp). Hint: lengthen output_interval_s or coarsen the mesh.");
}

/// Int dA of every film: the uniform state's film load (the area in the full space).
template <class Matrix>
std::vector<double> film_totals(const LinearThermalSystem<Matrix>& sys) {
  std::vector<double> film_total;
  for (const auto& a : sys.film_area) film_total.push_back(a.dot(sys.uniform));
  return film_total;
}

/// Checkpoints hold the base states only: refuse them with `nc` caller columns or readouts.
void require_checkpointable(const Checkpointing& checkpointing, const StepperRequest& q,
                            Eigen::Index nc, bool reads) {
  if ((checkpointing.save || checkpointing.resume) && (nc > 0 || reads || !q.record_states))
    throw core::SolverError(
        "thermal stepper: checkpoints hold the base states only; they cannot "
        "be used with caller columns or readouts");
}

/// Fills the first output time (t = 0) from the start's state, readouts and responses.
void record_start(SteppedHistory& hist, const Eigen::VectorXd& temp,
                  const Eigen::VectorXd& read_prev, const Dense& block_prev, bool record_states,
                  bool reads) {
  const auto nc = static_cast<Eigen::Index>(hist.responses.size());
  if (record_states) hist.states.col(0) = temp;
  if (reads) hist.readout.col(0) = read_prev;
  for (Eigen::Index j = 0; j < nc; ++j) hist.responses[j].col(0) = block_prev.col(j);
}

/// The recorded states, energy accumulators and step count of a checkpoint, into `hist`.
void restore_history(SteppedHistory& hist, const ThermalCheckpoint& c) {
  hist.states.leftCols(c.outputs.cols()) = c.outputs;
  hist.heat_in = c.heat_in;
  hist.lost = c.lost;
  hist.timings.steps = c.steps;
}

/// One time step [t_prev, t] of the grid, index `step`; t0_k: the initial temperature [K].
struct StepTimes {
  double t_prev, t, t0_k;
  std::size_t step;
};

/// The base state at the step's end from `temp` at its start: (C + theta dt K) next =
/// (C - (1 - theta) dt K) temp + load solved with the step's factor (`kk`: K), then the sources'
/// iteration when asked for (`source_iterations` keeps the most solves of one step). `rhs`:
/// scratch, #states. Throws SolverError when the state is not finite.
template <class Matrix>
Eigen::VectorXd solved_state(const LinearThermalSystem<Matrix>& sys, const core::CaseSpec& spec,
                             const StepperRequest& q, const StepFactor<Matrix>& factor,
                             const Matrix& kk, const Eigen::VectorXd& temp, StepPlan& p,
                             const StepTimes& st, Eigen::VectorXd& rhs, int& source_iterations) {
  const double dt = st.t - st.t_prev;
  rhs = sys.capacity * temp + p.load;
  if (p.theta != 1) rhs -= (0.5 * dt) * (kk * temp);
  Eigen::VectorXd next = rhs;
  factor.solve_in_place(next);
  if (q.sources.tolerance_K > 0 && next.allFinite())
    source_iterations = std::max(
        source_iterations,
        iterate_sources(spec, sys, q.sources, factor, st.t_prev, st.t, st.t0_k, rhs, p, next));
  if (!next.allFinite()) throw non_finite_temperature(spec, p.s_new, next, st.step, st.t);
  return next;
}

/// The output times (0, then the record times) with the recorded states, readouts and the `nc`
/// caller columns' responses allocated, none filled.
SteppedHistory allocated_history(const core::CaseSpec& spec, const StepperRequest& q,
                                 Eigen::Index n, Eigen::Index nc) {
  SteppedHistory hist;
  hist.times.push_back(0.0);
  hist.times.insert(hist.times.end(), q.record_times.begin(), q.record_times.end());
  const auto times = static_cast<Eigen::Index>(hist.times.size());
  if (q.record_states) {
    require_history_fits(spec, n, static_cast<std::size_t>(times));
    hist.states.resize(n, times);
  }
  hist.readout.resize(q.base_readout.rows(), times);
  for (Eigen::Index j = 0; j < nc; ++j) hist.responses.emplace_back(q.column_readout.rows(), times);
  return hist;
}

/// Adds one step's heat to the history's energy accumulators: in from the sources, moving loads
/// and surface fluxes, out through the films (`next`: the state at the step's end;
/// lost_rate_prev: the films' rate at its start, used by Crank–Nicolson).
template <class Matrix>
void add_step_heat(SteppedHistory& hist, const LinearThermalSystem<Matrix>& sys,
                   const core::CaseSpec& spec, const std::vector<double>& film_total,
                   const StepPlan& plan, const Eigen::VectorXd& next, double dt,
                   double lost_rate_prev) {
  const LoadState& s_new = plan.s_new;
  const bool cn = plan.theta != 1;
  double power = 0;
  for (double p : s_new.power) power += p;
  const double lost_new = convected_rate(sys, film_total, next, s_new);
  hist.heat_in += dt * (power + plan.f_moving.dot(sys.uniform));
  hist.lost += cn ? 0.5 * dt * (lost_rate_prev + lost_new) : dt * lost_new;
  // Surface fluxes enter as heat too.
  for (size_t j = 0; j < spec.thermal.fluxes.size(); ++j) {
    const auto& fl = spec.thermal.fluxes[j];
    hist.heat_in += dt * fl.flux * flux_scale(fl, s_new.speed) * sys.flux_area[j].dot(sys.uniform);
  }
}

/// The base state, readouts and caller-column responses at both ends of one step [t0, t1].
struct StepEnds {
  double t0, t1;
  const Eigen::VectorXd& state0;
  const Eigen::VectorXd& state1;
  const Eigen::VectorXd& read0;
  const Eigen::VectorXd& read1;
  const Dense& block0;
  const Dense& block1;
};

/// Fills the output times from `next_out` on that the step reaches (within 1e-9 `end`), linear
/// in time between its ends: the next output time's index.
size_t recorded_outputs(SteppedHistory& hist, size_t next_out, const StepEnds& e, double end,
                        bool record_states, bool reads) {
  const double t_prev = e.t0, t = e.t1, dt = t - t_prev;
  const auto nc = static_cast<Eigen::Index>(hist.responses.size());
  while (next_out < hist.times.size() && hist.times[next_out] <= t + 1e-9 * end) {
    const double w = (hist.times[next_out] - t_prev) / dt;
    const auto k = static_cast<Eigen::Index>(next_out);
    if (record_states) hist.states.col(k) = (1 - w) * e.state0 + w * e.state1;
    // Readouts are linear: interpolate them rather than the states (exact at a step end).
    if (reads) {
      if (w == 1)
        hist.readout.col(k) = e.read1;
      else
        hist.readout.col(k) = (1 - w) * e.read0 + w * e.read1;
    }
    for (Eigen::Index j = 0; j < nc; ++j) {
      if (w == 1)
        hist.responses[j].col(k) = e.block1.col(j);
      else
        hist.responses[j].col(k) = (1 - w) * e.block0.col(j) + w * e.block1.col(j);
    }
    ++next_out;
  }
  return next_out;
}

}  // namespace

template <class Matrix>
Eigen::VectorXd moving_heat_load(const core::CaseSpec& spec, const LinearThermalSystem<Matrix>& sys,
                                 double t0, double t1) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(sys.states());
  const double mid = 0.5 * (t0 + t1);
  const double speed = speed_at(spec.duty_cycle, mid), feed = feed_speed_at(spec.feed_axis, mid);
  for (size_t k = 0; k < sys.moving.size(); ++k) {
    const double power = source_power(spec.thermal.sources[sys.moving_source[k]], speed, feed);
    if (power == 0) continue;
    if constexpr (std::is_same_v<Matrix, Dense>) {
      // A reduced system's moving matrix is dense: one prefix difference per sub-instant.
      if (sys.moving_prefix.size() != sys.moving.size())
        throw core::SolverError(
            "reduced system without the prefix sums of its moving loads (with_moving_prefix)");
      const Dense& prefix = sys.moving_prefix[k];
      for (const WindowShare& w : moving_windows(spec, sys.moving_pieces[k], t0, t1))
        f += (w.per_volume * power) * (prefix.col(w.hi) - prefix.col(w.lo));
    } else {
      // Only the pieces under the window take heat.
      const Eigen::VectorXd share = moving_piece_fractions(spec, sys.moving_pieces[k], t0, t1);
      for (Eigen::Index p = 0; p < share.size(); ++p)
        if (share(p) != 0) f += (share(p) * power) * sys.moving[k].col(p);
    }
  }
  return f;
}

ReducedThermalSystem with_moving_prefix(ReducedThermalSystem reduced) {
  reduced.moving_prefix.clear();
  for (std::size_t k = 0; k < reduced.moving.size(); ++k)
    reduced.moving_prefix.push_back(moving_prefix(reduced.moving[k], reduced.moving_pieces[k]));
  return reduced;
}

template <class Matrix>
StepLoad step_load(const LinearThermalSystem<Matrix>& sys, const core::CaseSpec& spec, double t0,
                   double t1, const Eigen::VectorXd& state0) {
  const double t0_k = spec.thermal.initial_temperature_c + core::kCelsiusOffset;
  const LoadState s = load_state(spec, sys, 0.5 * (t0 + t1), t1, state0, t0_k);
  return {load_vector(spec, sys, s) + moving_heat_load(spec, sys, t0, t1), s.h};
}

template <class Matrix>
struct KeptStepFactors<Matrix>::Impl {
  LinearThermalSystem<Matrix> system;  /// the matrices the operators were made for
  std::optional<StepOperators<Matrix>> ops;

  /// The kept operators for stepping `sys`, counted in `timings`: made anew when `sys` has other
  /// matrices than the ones they were made for.
  StepOperators<Matrix>& for_system(const LinearThermalSystem<Matrix>& sys,
                                    ThermalTimings& timings) {
    if (ops && same_operators(system, sys)) {
      ops->rebind(system, timings);
      return *ops;
    }
    system.capacity = sys.capacity;
    system.conduction = sys.conduction;
    system.film = sys.film;
    return ops.emplace(system, timings);
  }
};

template <class Matrix>
KeptStepFactors<Matrix>::KeptStepFactors() : impl_(std::make_unique<Impl>()) {}
template <class Matrix>
KeptStepFactors<Matrix>::~KeptStepFactors() = default;

template <class Matrix>
SteppedHistory step_thermal(const LinearThermalSystem<Matrix>& sys, const core::CaseSpec& spec,
                            const StepperRequest& q, const Progress& progress,
                            const Checkpointing& checkpointing, KeptStepFactors<Matrix>* kept) {
  const Eigen::Index n = sys.states();
  const double t0_k = spec.thermal.initial_temperature_c + core::kCelsiusOffset;
  const double end = spec.duty_cycle.end;
  check_request(sys, q, end);
  const std::vector<double> grid = time_grid(spec, spec.thermal.step);
  const Eigen::Index ns = static_cast<Eigen::Index>(q.shape_columns.size());
  const Eigen::Index nc = ns + static_cast<Eigen::Index>(q.load_columns.size());
  const bool reads = q.base_readout.rows() > 0;
  require_checkpointable(checkpointing, q, nc, reads);
  const std::vector<double> film_total = film_totals(sys);

  SteppedHistory hist = allocated_history(spec, q, n, nc);
  const Eigen::VectorXd start = t0_k * sys.uniform;
  Eigen::VectorXd temp = start;
  Dense x = Dense::Zero(n, nc);  // responses start from zero
  Eigen::VectorXd read_prev = reads ? read_state(q.base_readout, temp, start) : Eigen::VectorXd();
  Dense block_prev = nc ? read_block(q.column_readout, x) : Dense();
  record_start(hist, temp, read_prev, block_prev, q.record_states, reads);
  size_t next_out = 1;

  std::optional<StepOperators<Matrix>> own;
  StepOperators<Matrix>& ops =
      kept ? kept->impl().for_system(sys, hist.timings) : own.emplace(sys, hist.timings);

  const auto t_solve = Clock::now();
  double t_prev = 0, prev_speed = std::nan("");
  double lost_rate_prev = 0;  // heat rate out at t_prev under the current interval's h (CN)
  size_t first_step = 0;
  if (const ThermalCheckpoint* c = checkpointing.resume) {
    check_resume(*c, n, grid, hist.times.size());
    first_step = static_cast<size_t>(c->steps);
    t_prev = c->time;
    prev_speed = c->speed;
    temp = c->temperature;
    next_out = static_cast<size_t>(c->outputs.cols());
    restore_history(hist, *c);
  }
  auto t_saved = Clock::now();
  Eigen::VectorXd rhs(n), read_new;
  Dense block_new;
  for (size_t i = first_step; i < grid.size(); ++i) {
    const double t = grid[i], dt = t - t_prev;
    StepPlan p = step_plan(spec, sys, t_prev, t, i == 0 ? std::nan("") : prev_speed, temp, t0_k);
    const LoadState& s_new = p.s_new;
    const bool cn = p.theta != 1;
    const double theta = p.theta;
    const Matrix& kk = ops.stiffness(s_new);
    if (cn) lost_rate_prev = convected_rate(sys, film_total, temp, p.s_old);
    const StepFactor<Matrix>& factor = ops.factor(dt, theta, s_new);
    Eigen::VectorXd next = solved_state(sys, spec, q, factor, kk, temp, p, {t_prev, t, t0_k, i},
                                        rhs, hist.source_iterations);
    if (nc > 0)
      x = stepped_responses(sys, q, {t_prev, t, s_new.speed, theta, &temp, &next}, kk, factor, x);
    add_step_heat(hist, sys, spec, film_total, p, next, dt, lost_rate_prev);

    if (reads) read_new = read_state(q.base_readout, next, start);
    if (nc) block_new = read_block(q.column_readout, x);
    next_out = recorded_outputs(hist, next_out,
                                {t_prev, t, temp, next, read_prev, read_new, block_prev, block_new},
                                end, q.record_states, reads);
    temp.swap(next);
    if (reads) read_prev.swap(read_new);
    if (nc) block_prev.swap(block_new);
    t_prev = t;
    prev_speed = s_new.speed;
    hist.timings.steps += 1;
    if (progress) progress(t, end);
    if (checkpointing.save && i + 1 < grid.size() &&
        seconds_since(t_saved) >= checkpointing.interval_s) {
      const auto cols = static_cast<Eigen::Index>(next_out);
      checkpointing.save({static_cast<int>(i + 1), t, prev_speed, temp, hist.states.leftCols(cols),
                          hist.heat_in, hist.lost});
      t_saved = Clock::now();
    }
  }
  hist.timings.solve_s = seconds_since(t_solve) - hist.timings.factor_s;
  hist.final_state = std::move(temp);
  return hist;
}

struct ReducedStepper::Impl {
  const ReducedThermalSystem& sys;
  const core::CaseSpec& spec;
  ThermalTimings timings;
  StepOperators<Dense> ops;
  std::map<std::tuple<double, double, double>, Dense> transitions;
  Impl(const ReducedThermalSystem& s, const core::CaseSpec& c) : sys(s), spec(c), ops(s, timings) {}
};

ReducedStepper::ReducedStepper(const ReducedThermalSystem& system, const core::CaseSpec& spec)
    : impl_(std::make_unique<Impl>(system, spec)) {}
ReducedStepper::~ReducedStepper() = default;

AffineStep ReducedStepper::step(double t0, double t1, double prev_speed,
                                const Eigen::VectorXd& state) {
  Impl& m = *impl_;
  if (!(t1 > t0))
    throw core::SolverError("reduced step from t = " + std::to_string(t0) + " s to " +
                            std::to_string(t1) + " s: the end must be after the start");
  // A stream's steps and speeds need not repeat (jittered times, a measured speed): the kept
  // operators are bounded, forgotten all at once when there are this many.
  constexpr std::size_t kKept = 64;
  if (m.transitions.size() >= kKept) {
    m.transitions.clear();
    m.ops.forget();
  }
  const double dt = t1 - t0;
  const double t0_k = m.spec.thermal.initial_temperature_c + core::kCelsiusOffset;
  const StepPlan p = step_plan(m.spec, m.sys, t0, t1, prev_speed, state, t0_k);
  const StepFactor<Dense>& factor = m.ops.factor(dt, p.theta, p.s_new);
  const auto key = std::make_tuple(std::round(dt * 1e9) / 1e9, p.s_new.speed, p.theta);
  auto it = m.transitions.find(key);
  if (it == m.transitions.end()) {
    Dense right = m.sys.capacity;
    if (p.theta != 1) right -= ((1 - p.theta) * dt) * m.ops.stiffness(p.s_new);
    it = m.transitions.emplace(key, factor.inverse() * right).first;
  }
  AffineStep a;
  a.t0 = t0;
  a.t1 = t1;
  a.speed = p.s_new.speed;
  a.theta = p.theta;
  a.film = p.s_new.h;
  a.step_inverse = &factor.inverse();
  a.transition = &it->second;
  a.input = factor.inverse() * p.load;
  return a;
}

template SteppedHistory step_thermal<Sparse>(const FullThermalSystem&, const core::CaseSpec&,
                                             const StepperRequest&, const Progress&,
                                             const Checkpointing&, KeptStepFactors<Sparse>*);
template SteppedHistory step_thermal<Dense>(const ReducedThermalSystem&, const core::CaseSpec&,
                                            const StepperRequest&, const Progress&,
                                            const Checkpointing&, KeptStepFactors<Dense>*);
template class KeptStepFactors<Sparse>;
template class KeptStepFactors<Dense>;
template Eigen::VectorXd moving_heat_load<Sparse>(const core::CaseSpec&, const FullThermalSystem&,
                                                  double, double);
template Eigen::VectorXd moving_heat_load<Dense>(const core::CaseSpec&, const ReducedThermalSystem&,
                                                 double, double);

template StepLoad step_load<Sparse>(const FullThermalSystem&, const core::CaseSpec&, double, double,
                                    const Eigen::VectorXd&);
template StepLoad step_load<Dense>(const ReducedThermalSystem&, const core::CaseSpec&, double,
                                   double, const Eigen::VectorXd&);

}  // namespace tt::solvers
