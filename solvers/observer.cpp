#include "solvers/observer.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <optional>
#include <string>

#include "core/dense_product.hpp"
#include "core/directions.hpp"
#include "core/errors.hpp"
#include "core/units.hpp"
#include "solvers/loads.hpp"

namespace tt::solvers {

namespace {

/// Quantile p of the standard normal distribution (bisection on erfc: called once per window).
double normal_quantile(double p) {
  double lo = -10, hi = 10;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::string number(double v) {
  return std::to_string(v);
}

/// Columns of the unknown heat inputs, r x #inputs [state per W]: one per fixed source (on its
/// shape) and one per film (1 W spread over its surface by area); their names go to `names`.
Eigen::MatrixXd unknown_heat_columns(const ReducedThermalSystem& system, const core::CaseSpec& spec,
                                     std::vector<std::string>& names) {
  std::vector<Eigen::VectorXd> heat;
  for (std::size_t i = 0; i < system.source_shape.size(); ++i) {
    if (spec.thermal.sources[i].window > 0) continue;  // moving: its pieces, not a shape
    heat.push_back(system.source_shape[i]);
    names.push_back("heat:" + spec.thermal.sources[i].name);
  }
  const auto& conv = spec.thermal.convection;
  for (std::size_t c = 0; c < system.film_area.size(); ++c) {
    const double area = system.film_area[c].dot(system.uniform);
    if (!(area > 0)) continue;
    heat.push_back(system.film_area[c] / area);
    names.push_back("heat:" + spec.groups[conv[c].group].name);
  }
  Eigen::MatrixXd columns(system.states(), static_cast<Eigen::Index>(heat.size()));
  for (std::size_t k = 0; k < heat.size(); ++k) columns.col(static_cast<Eigen::Index>(k)) = heat[k];
  return columns;
}

/// The per-material target rows of the target rows' shape; ObserverNoise::expansion_relative_sigma
/// (when given) one finite value >= 0 per material, and the per-material rows there when one is
/// above 0; SolverError otherwise.
void check_expansion_rows(const ObserverSetup& s) {
  for (const Eigen::MatrixXd& part : s.target_expansion)
    if (part.rows() != s.target_rows.rows() || part.cols() != s.target_rows.cols())
      throw core::SolverError("observer: drift rows per material of " +
                              std::to_string(part.rows()) + " x " + std::to_string(part.cols()) +
                              ", the target rows " + std::to_string(s.target_rows.rows()) + " x " +
                              std::to_string(s.target_rows.cols()));
  const Eigen::VectorXd& e = s.noise.expansion_relative_sigma;
  if (!e.allFinite() || (e.array() < 0).any())
    throw core::SolverError("observer: an expansion relative sigma is negative or not finite");
  if ((e.array() == 0).all()) return;
  if (s.target_expansion.empty())
    throw core::SolverError(
        "observer: an expansion relative sigma needs the drift rows per material, which this "
        "reduced model does not keep (written before they were); rebuild it with `thermotwin "
        "reduce`");
  if (static_cast<std::size_t>(e.size()) != s.target_expansion.size())
    throw core::SolverError("observer: " + std::to_string(e.size()) +
                            " expansion relative sigmas for " +
                            std::to_string(s.target_expansion.size()) + " materials");
}

}  // namespace

std::vector<int> air_entries(const core::CaseSpec& spec) {
  std::vector<int> out;
  const auto& fixed = spec.mechanical.fixed_groups;
  for (std::size_t c = 0; c < spec.thermal.convection.size(); ++c)
    if (std::find(fixed.begin(), fixed.end(), spec.thermal.convection[c].group) == fixed.end())
      out.push_back(static_cast<int>(c));
  return out;
}

Eigen::RowVectorXd twin_point_row(const Twin& twin,
                                  const std::vector<std::pair<int, double>>& weights) {
  const Eigen::MatrixXd& basis = twin.model.basis;
  Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(basis.cols());
  for (const auto& [node, w] : weights) {
    if (node < 0 || node >= basis.rows())
      throw core::SolverError("observer: node " + std::to_string(node) +
                              " is not a node of the reduced model's basis (" +
                              std::to_string(basis.rows()) + " nodes)");
    row += w * basis.row(node);
  }
  return row;
}

ObserverSetup twin_observer_setup(const Twin& twin, const core::CaseSpec& spec,
                                  const std::vector<std::string>& sensors,
                                  const ObserverNoise& noise, const Eigen::MatrixXd& sensor_rows) {
  const TwinOutputs& out = twin.outputs;
  if (!out.tcp)
    throw core::SolverError(
        "observer: the reduced model has no TCP rows (mechanical.enabled and mechanical.tcp in "
        "the case it was built from): there is no drift to predict");
  ObserverSetup s;
  s.sensor_rows.resize(static_cast<Eigen::Index>(sensors.size()), out.rows.cols());
  if (sensor_rows.size() != 0 &&
      (sensor_rows.rows() != s.sensor_rows.rows() || sensor_rows.cols() != out.rows.cols()))
    throw core::SolverError("observer: " + std::to_string(sensor_rows.rows()) + " x " +
                            std::to_string(sensor_rows.cols()) + " sensor rows for " +
                            std::to_string(sensors.size()) + " sensors of a twin of " +
                            std::to_string(out.rows.cols()) + " states");
  if (sensor_rows.size() != 0) {
    s.sensor_rows = sensor_rows;
  } else {
    for (std::size_t k = 0; k < sensors.size(); ++k) {
      const int row = temperature_row(out, sensors[k]);
      if (row < 0) {
        std::string known;
        for (int n = 0; n < out.temperatures; ++n)
          known += (known.empty() ? "" : ", ") + out.names[static_cast<std::size_t>(n)];
        throw core::SolverError("observer: sensor '" + sensors[k] +
                                "' is not a named point of the reduced model; expected one of " +
                                known);
      }
      s.sensor_rows.row(static_cast<Eigen::Index>(k)) = out.rows.row(row);
    }
  }
  const Eigen::Index first = out.temperatures;
  const Eigen::Index axis = static_cast<Eigen::Index>(out.names.size()) - first - 9;
  // The TCP's three rows and the axis points' (after the two probes' six).
  const auto targets = [&](const Eigen::MatrixXd& displacement_rows) {
    Eigen::MatrixXd t(3 + axis, displacement_rows.cols());
    t.topRows(3) = displacement_rows.topRows(3);
    t.bottomRows(axis) = displacement_rows.bottomRows(axis);
    return t;
  };
  s.target_rows = targets(out.rows.bottomRows(out.rows.rows() - first));
  for (const Eigen::MatrixXd& part : out.expansion) s.target_expansion.push_back(targets(part));
  s.expansion_materials = out.materials;
  s.target_names.assign(std::begin(core::kDirectionNames), std::end(core::kDirectionNames));
  for (Eigen::Index k = 0; k < axis; ++k)
    s.target_names.push_back(out.names[static_cast<std::size_t>(first + 9 + k)]);
  s.air_entries = air_entries(spec);
  s.sensor_names = sensors;
  s.noise = noise;
  return s;
}

double chi_square_quantile(double p, double k) {
  if (!(k > 0) || !(p > 0 && p < 1))
    throw core::SolverError("chi-square quantile p = " + number(p) + ", k = " + number(k) +
                            ": expected 0 < p < 1 and k > 0");
  const double z = normal_quantile(p), a = 2.0 / (9.0 * k);
  const double c = 1 - a + z * std::sqrt(a);
  return k * std::max(0.0, c * c * c);
}

bool InnovationMonitor::add(double t, double nis, int dof) {
  if (dof <= 0) return alarm_;  // nothing read: the window is unchanged
  t_.push_back(t);
  nis_.push_back(nis);
  dof_.push_back(dof);
  sum_ += nis;
  dof_sum_ += dof;
  while (first_ < t_.size() && t_[first_] <= t - o_.window_s) {
    sum_ -= nis_[first_];
    dof_sum_ -= dof_[first_];
    ++first_;
  }
  // A window is judged once it is full: a few samples of a fresh start say little.
  const bool full = t - t_.front() >= o_.window_s;
  bound_ = chi_square_quantile(o_.probability, dof_sum_);
  if (full && sum_ > bound_) {
    if (std::isnan(exceed_start_)) exceed_start_ = t;
    if (!alarm_ && t - exceed_start_ >= o_.sustain_s) {
      alarm_ = true;
      alarm_start_ = change_start();
    }
  } else {
    exceed_start_ = std::numeric_limits<double>::quiet_NaN();
  }
  return alarm_;
}

double InnovationMonitor::change_start() const {
  // The change point of a shift in the NIS's mean: where the cumulative excess over its
  // expectation, sum (NIS - dof), is lowest; the change starts at the next sample.
  double sum = 0, lowest = 0;
  std::size_t after = 0;
  for (std::size_t k = 0; k < t_.size(); ++k) {
    sum += nis_[k] - dof_[k];
    if (sum <= lowest) {  // the latest of equal lows: a flat stretch is before the change
      lowest = sum;
      after = k + 1;
    }
  }
  return t_[std::min(after, t_.size() - 1)];
}

std::vector<HeldSensor> HeldBeyondMonitor::add(double t,
                                               const Eigen::Ref<const Eigen::VectorXd>& value,
                                               const Eigen::Ref<const Eigen::VectorXd>& sigma) {
  std::vector<HeldSensor> now;
  if (!(sigmas_ > 0)) return now;
  const auto n = static_cast<std::size_t>(value.size());
  beyond_since_.resize(n, std::numeric_limits<double>::quiet_NaN());
  within_onset_.resize(n, t);
  raised_.resize(n, false);
  const auto beyond = [&](std::size_t k) {
    const auto i = static_cast<Eigen::Index>(k);
    return std::abs(value(i)) > sigmas_ * sigma(i);
  };
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    if (!raised_[k] && std::abs(value(i)) <= onset_sigmas_ * sigma(i)) within_onset_[k] = t;
  }
  // Exclusive: several sensors not yet raised beyond the bound together are heat or air read as
  // offsets, more likely than several sensors failing at once; none of them is counted.
  std::size_t together = 0;
  for (std::size_t k = 0; k < n; ++k) together += !raised_[k] && beyond(k);
  for (std::size_t k = 0; k < n; ++k) {
    if (!beyond(k) || (exclusive_ && together > 1 && !raised_[k])) {
      beyond_since_[k] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    if (std::isnan(beyond_since_[k])) beyond_since_[k] = t;
    if (!raised_[k] && t - beyond_since_[k] >= sustain_s_) {
      raised_[k] = true;
      const double onset =
          onset_sigmas_ > 0 ? std::min(within_onset_[k], beyond_since_[k]) : beyond_since_[k];
      now.push_back({static_cast<int>(k), beyond_since_[k], t, onset});
    }
  }
  held_.insert(held_.end(), now.begin(), now.end());
  return now;
}

namespace {

/// Throws SolverError naming what of `setup` does not fit `system` and `spec`, or is not a
/// finite noise, bound or scale.
void check_setup(const ReducedThermalSystem& system, const core::CaseSpec& spec,
                 const ObserverSetup& setup) {
  const Eigen::Index r = system.states();
  const auto fail = [](const std::string& what) { throw core::SolverError("observer: " + what); };
  if (setup.sensor_rows.cols() != r || setup.target_rows.cols() != r)
    fail("the sensor and target rows have " + std::to_string(setup.sensor_rows.cols()) + " and " +
         std::to_string(setup.target_rows.cols()) + " columns, the reduced model " +
         std::to_string(r) + " states: rows of another model");
  if (static_cast<std::size_t>(setup.target_rows.rows()) != setup.target_names.size())
    fail(std::to_string(setup.target_rows.rows()) + " target rows for " +
         std::to_string(setup.target_names.size()) + " names");
  const auto& sigma = setup.noise.sensor_sigma_k;
  if (sigma.size() != setup.sensor_rows.rows() || !(sigma.array() > 0).all() || !sigma.allFinite())
    fail("sensor noise: " + std::to_string(sigma.size()) + " values for " +
         std::to_string(setup.sensor_rows.rows()) +
         " sensors; expected one finite sigma > 0 K each");
  const ObserverNoise& n = setup.noise;
  for (double v : {n.heat_walk_w, n.heat_initial_w, n.air_walk_k, n.air_initial_k, n.state_walk_k,
                   n.drift_relative_sigma, n.sensor_offset_initial_k, n.sensor_offset_walk_k,
                   n.correction_relative_sigma})
    if (!(v >= 0) || !std::isfinite(v))
      fail("process noise " + number(v) + ": expected a finite value >= 0");
  for (double bound :
       {setup.consistency.sensor_fault_sigmas, setup.consistency.model_residual_sigmas,
        setup.consistency.departure_onset_sigmas})
    if (!(bound >= 0) || !std::isfinite(bound))
      fail("sensor fault, model residual or departure onset bound " + number(bound) +
           " sigma: expected a finite value >= 0");
  check_expansion_rows(setup);
  for (const Eigen::VectorXd* scale : {&n.drift_sigma_scale, &n.probed_drift_sigma_scale})
    if (scale->size() != 0 && (scale->size() != setup.target_rows.rows() ||
                               !(scale->array() > 0).all() || !scale->allFinite()))
      fail("drift sigma scale: " + std::to_string(scale->size()) + " values for " +
           std::to_string(setup.target_rows.rows()) +
           " targets; expected none or one finite factor > 0 per target");
  const auto& conv = spec.thermal.convection;
  for (int c : setup.air_entries)
    if (c < 0 || c >= static_cast<int>(conv.size()) ||
        static_cast<std::size_t>(c) >= system.film_area.size())
      fail("air entry " + std::to_string(c) + " is not a convection entry (the case has " +
           std::to_string(conv.size()) + ")");

  const Eigen::Index m = setup.sensor_rows.rows();
  if (!setup.sensor_names.empty() && setup.sensor_names.size() != static_cast<std::size_t>(m))
    fail(std::to_string(setup.sensor_names.size()) + " sensor names for " + std::to_string(m) +
         " sensor rows");
}

}  // namespace

KalmanObserver::KalmanObserver(const ReducedThermalSystem& system, const core::CaseSpec& spec,
                               const ObserverSetup& setup)
    : sys_(system),
      spec_(spec),
      setup_(setup),
      stepper_(system, spec),
      monitor_(setup.consistency),
      faults_(setup.consistency.sensor_fault_sigmas, setup.consistency.sustain_s),
      departures_(setup.consistency.model_residual_sigmas, setup.consistency.sustain_s, false,
                  setup.consistency.departure_onset_sigmas),
      evidence_(evidence_settings(setup.consistency)) {
  r_ = system.states();
  check_setup(system, spec, setup_);
  const ObserverNoise& n = setup_.noise;
  const Eigen::Index m = setup_.sensor_rows.rows();

  heat_columns_ = unknown_heat_columns(system, spec, bias_names_);
  const bool air = !setup_.air_entries.empty();
  if (air) bias_names_.push_back("air");
  const bool offsets = n.sensor_offset_initial_k > 0 || n.sensor_offset_walk_k > 0;
  offsets_ = offsets ? static_cast<Eigen::Index>(bias_names_.size()) : -1;
  if (offsets)
    for (Eigen::Index k = 0; k < m; ++k)
      bias_names_.push_back("offset:" + (setup_.sensor_names.empty()
                                             ? std::to_string(k)
                                             : setup_.sensor_names[static_cast<std::size_t>(k)]));
  nb_ = static_cast<Eigen::Index>(bias_names_.size());
  bias_walk_.resize(nb_);
  const Eigen::Index nh = heat_columns_.cols();
  bias_walk_.head(nh).setConstant(n.heat_walk_w * n.heat_walk_w / 3600.0);
  if (air) bias_walk_(nh) = n.air_walk_k * n.air_walk_k / 3600.0;
  if (offsets)
    bias_walk_.segment(offsets_, m)
        .setConstant(n.sensor_offset_walk_k * n.sensor_offset_walk_k / 3600.0);

  const double t0_k = std::isnan(setup_.initial_temperature_k)
                          ? spec.thermal.initial_temperature_c + core::kCelsiusOffset
                          : setup_.initial_temperature_k;
  z0_ = t0_k * system.uniform;
  z_open_ = z0_;
  x_ = Eigen::VectorXd::Zero(r_ + nb_);
  x_.head(r_) = z0_;
  p_ = Eigen::MatrixXd::Zero(r_ + nb_, r_ + nb_);
  for (Eigen::Index k = 0; k < nh; ++k) p_(r_ + k, r_ + k) = n.heat_initial_w * n.heat_initial_w;
  if (air) p_(r_ + nh, r_ + nh) = n.air_initial_k * n.air_initial_k;
  if (offsets)
    p_.diagonal()
        .segment(r_ + offsets_, m)
        .setConstant(n.sensor_offset_initial_k * n.sensor_offset_initial_k);
}

namespace {

/// F P F^T for F = [[phi, gamma], [0, I]], by blocks (r states, then the unknown inputs).
Eigen::MatrixXd propagated(const Eigen::MatrixXd& p, const Eigen::MatrixXd& phi,
                           const Eigen::MatrixXd& gamma) {
  const Eigen::Index r = phi.rows(), nb = gamma.cols();
  const auto pzz = p.topLeftCorner(r, r), pzb = p.topRightCorner(r, nb),
             pbb = p.bottomRightCorner(nb, nb);
  // core::dense_product: coefficient-wise for ~100 rows (Eigen's OpenMP-parallel GEMM's threads
  // wait on each other every step when the cores are shared), blocked for several hundred.
  const Eigen::MatrixXd left =
      core::dense_product(phi, pzz) + gamma.lazyProduct(pzb.transpose());       // r x r
  const Eigen::MatrixXd cross = phi.lazyProduct(pzb) + gamma.lazyProduct(pbb);  // r x nb
  const Eigen::MatrixXd zz =
      core::dense_product(left, phi.transpose()) + cross.lazyProduct(gamma.transpose());
  Eigen::MatrixXd out(p.rows(), p.cols());
  out.topLeftCorner(r, r) = 0.5 * (zz + zz.transpose());
  out.topRightCorner(r, nb) = cross;
  out.bottomLeftCorner(nb, r) = cross.transpose();
  out.bottomRightCorner(nb, nb) = pbb;
  return out;
}

}  // namespace

void KalmanObserver::add_process_noise(Eigen::MatrixXd& p, double dt) const {
  const double walk = setup_.noise.state_walk_k;
  if (walk > 0) p.topLeftCorner(r_, r_).diagonal().array() += walk * walk / 3600.0 * dt;
  p.bottomRightCorner(nb_, nb_).diagonal() += bias_walk_ * dt;
}

void KalmanObserver::step(double t1) {
  const AffineStep a = stepper_.step(t_, t1, prev_speed_, x_.head(r_));
  const double dt = t1 - t_;
  // Unknown inputs' columns over this step: the air's follows the step's film coefficients.
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(r_, nb_);  // the sensor offsets: no heat
  const Eigen::Index nh = heat_columns_.cols();
  b.leftCols(nh) = heat_columns_;
  if (nb_ > nh) {
    Eigen::VectorXd air = Eigen::VectorXd::Zero(r_);
    for (int c : setup_.air_entries) air += a.film[static_cast<std::size_t>(c)] * sys_.film_area[c];
    b.col(nh) = air;
  }
  const Eigen::MatrixXd gamma = (*a.step_inverse).lazyProduct(dt * b);
  const Eigen::MatrixXd& phi = *a.transition;
  // x1 = F x0 + [u; 0], F = [[Phi, Gamma], [0, I]]; P1 = F P0 F^T + Q.
  Eigen::VectorXd z = phi * x_.head(r_) + a.input + gamma * x_.tail(nb_);
  p_ = propagated(p_, phi, gamma);
  add_process_noise(p_, dt);
  if (map_) {
    Eigen::MatrixXd& f = map_->transition;
    f.topRows(r_) = core::dense_product(phi, f.topRows(r_)) + gamma.lazyProduct(f.bottomRows(nb_));
    map_->process = propagated(map_->process, phi, gamma);
    add_process_noise(map_->process, dt);
  }
  x_.head(r_) = std::move(z);
  z_open_ = (phi * z_open_ + a.input).eval();
  t_ = t1;
  prev_speed_ = a.speed;
}

void KalmanObserver::advance_to(double t) {
  const double end = spec_.duty_cycle.end, eps = 1e-9 * std::max(1.0, end);
  if (t < t_ - eps)
    throw core::SolverError("observer: a reading at t = " + number(t) +
                            " s comes after one at t = " + number(t_) +
                            " s; expected increasing times");
  if (t > end + eps)
    throw core::SolverError("observer: a reading at t = " + number(t) +
                            " s is beyond the duty cycle's end (" + number(end) +
                            " s): the inputs are not known there");
  // Steps of at most the case's step, equal between the load's switches and the reading, each
  // from what is known by then: a duty cycle read as the samples come steps as the whole run.
  const double max_step = spec_.thermal.step;
  while (t_ < t - eps) {
    const double b = std::min(t, next_switch(spec_, t_ + eps));
    const double k = std::max(1.0, std::ceil((b - t_) / max_step - 1e-9));
    step(k > 1 ? t_ + (b - t_) / k : b);
  }
}

std::vector<UnknownInputKind> KalmanObserver::unknown_input_kinds() const {
  const Eigen::Index nh = heat_columns_.cols();
  std::vector<UnknownInputKind> kinds(static_cast<std::size_t>(nb_));
  for (Eigen::Index k = 0; k < nb_; ++k)
    kinds[static_cast<std::size_t>(k)] =
        k < nh ? UnknownInputKind::heat
               : (offsets_ >= 0 && k >= offsets_ ? UnknownInputKind::sensor_offset
                                                 : UnknownInputKind::air);
  return kinds;
}

namespace {

/// The rows an assimilation reads (`used`: sensor k < #sensors, drift reading #sensors + target),
/// without the offsets: H, the innovations y - H z (a drift reading's relative to t = 0, d - L (z -
/// z(0))) and the readings' variances (a drift reading's with the rows' own relative error at the
/// predicted drift).
struct MeasurementRows {
  Eigen::MatrixXd h;
  Eigen::VectorXd innovation, variance;
};

MeasurementRows measurement_rows(const ObserverSetup& setup, const Eigen::VectorXd& z,
                                 const Eigen::VectorXd& z0, const std::vector<Eigen::Index>& used,
                                 const Eigen::VectorXd& readings,
                                 const Eigen::VectorXd& drift_readings) {
  const Eigen::Index m = setup.sensor_rows.rows();
  const auto nu = static_cast<Eigen::Index>(used.size());
  const ObserverNoise& n = setup.noise;
  MeasurementRows out{Eigen::MatrixXd(nu, z.size()), Eigen::VectorXd(nu), Eigen::VectorXd(nu)};
  for (Eigen::Index i = 0; i < nu; ++i) {
    const Eigen::Index k = used[static_cast<std::size_t>(i)];
    if (k < m) {
      out.h.row(i) = setup.sensor_rows.row(k);
      out.innovation(i) = readings(k) - out.h.row(i).dot(z);
      out.variance(i) = n.sensor_sigma_k(k) * n.sensor_sigma_k(k);
    } else {
      out.h.row(i) = setup.target_rows.row(k - m);
      const double predicted = out.h.row(i).dot(z - z0);
      out.innovation(i) = drift_readings(k - m) - predicted;
      out.variance(i) = n.drift_reading_sigma_m * n.drift_reading_sigma_m +
                        std::pow(n.drift_relative_sigma * predicted, 2);
    }
  }
  return out;
}

}  // namespace

ObserverEstimate KalmanObserver::assimilate(double t, const Eigen::VectorXd& readings,
                                            const Eigen::VectorXd& drift_readings) {
  const Eigen::Index m = setup_.sensor_rows.rows(), nt = setup_.target_rows.rows();
  if (readings.size() != m)
    throw core::SolverError("observer: " + std::to_string(readings.size()) + " readings for " +
                            std::to_string(m) + " sensors");
  if (drift_readings.size() != 0 && drift_readings.size() != nt)
    throw core::SolverError("observer: " + std::to_string(drift_readings.size()) +
                            " drift readings for " + std::to_string(nt) + " targets");
  advance_to(t);
  ObserverEstimate e;
  e.time = t;
  update(t, readings, drift_readings, e);
  e.drift = setup_.target_rows * (x_.head(r_) - z0_);
  e.sigma_terms = drift_sigma_terms(e.drift);
  e.recalibrate = monitor_.add(t, e.nis, e.dof);
  if (setup_.noise.widen_on_inconsistency && monitor_.window_dof() > 0)
    e.sigma_terms.widening =
        std::sqrt(std::max(1.0, monitor_.window_nis() / monitor_.window_dof()));
  e.recalibrate_since_s = monitor_.since_s();
  test_departures(t, readings, e);
  e.sigma_terms.alarm = e.recalibrate;
  e.drift_sigma = drift_sigma(e.sigma_terms, setup_.noise.correction_relative_sigma,
                              setup_.noise.expansion_relative_sigma, setup_.noise.changed_terms);
  return e;
}

void KalmanObserver::update(double t, const Eigen::VectorXd& readings,
                            const Eigen::VectorXd& drift_readings, ObserverEstimate& e) {
  const Eigen::Index m = setup_.sensor_rows.rows(), nt = setup_.target_rows.rows();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  e.innovation = Eigen::VectorXd::Constant(m, nan);
  if (drift_readings.size() != 0)
    e.drift_innovation = e.drift_innovation_sigma = Eigen::VectorXd::Constant(nt, nan);
  // The rows read: the sensors' (k < m) and the drift readings' (m + target).
  std::vector<Eigen::Index> used;
  for (Eigen::Index k = 0; k < m; ++k)
    if (std::isfinite(readings(k))) used.push_back(k);
  for (Eigen::Index k = 0; k < drift_readings.size(); ++k)
    if (std::isfinite(drift_readings(k))) used.push_back(m + k);
  const auto nu = static_cast<Eigen::Index>(used.size());
  if (nu == 0) return;
  const auto [h, innovation0, r2] =
      measurement_rows(setup_, x_.head(r_), z0_, used, readings, drift_readings);
  Eigen::VectorXd innovation = innovation0;
  Eigen::MatrixXd pht = p_.leftCols(r_).lazyProduct(h.transpose());  // (r + nb) x nu
  // With offsets a reading is H z + o: its row has a 1 at its sensor's offset, so P H^T gains
  // that offset's column of P, and H P H^T that offset's row of P H^T (drift readings have none).
  const auto offset_of = [&](Eigen::Index i) {
    const Eigen::Index k = used[static_cast<std::size_t>(i)];
    return offsets_ >= 0 && k < m ? r_ + offsets_ + k : Eigen::Index{-1};
  };
  for (Eigen::Index i = 0; i < nu; ++i)
    if (const Eigen::Index o = offset_of(i); o >= 0) {
      innovation(i) -= x_(o);
      pht.col(i) += p_.col(o);
    }
  Eigen::MatrixXd s = h.lazyProduct(pht.topRows(r_));
  for (Eigen::Index i = 0; i < nu; ++i)
    if (const Eigen::Index o = offset_of(i); o >= 0) s.row(i) += pht.row(o);
  s.diagonal() += r2;
  const Eigen::LLT<Eigen::MatrixXd> llt(s);
  if (llt.info() != Eigen::Success)
    throw core::SolverError("observer: the innovation covariance at t = " + number(t) +
                            " s is not positive definite");
  for (Eigen::Index i = 0; i < nu; ++i) {
    const Eigen::Index k = used[static_cast<std::size_t>(i)];
    if (k < m) {
      e.innovation(k) = innovation(i);
    } else {
      e.drift_innovation(k - m) = innovation(i);
      e.drift_innovation_sigma(k - m) = std::sqrt(s(i, i));
    }
  }
  const Eigen::MatrixXd gain = llt.solve(pht.transpose()).transpose();  // (r + nb) x nu
  x_ += gain * innovation;
  p_ -= gain.lazyProduct(pht.transpose());
  p_ = 0.5 * (p_ + p_.transpose()).eval();
  e.nis = innovation.dot(llt.solve(innovation));
  e.dof = static_cast<int>(nu);
}

void KalmanObserver::test_departures(double t, const Eigen::VectorXd& readings,
                                     ObserverEstimate& e) {
  const Eigen::Index m = setup_.sensor_rows.rows();
  const auto earliest = [this](double since_s) {
    if (std::isnan(departure_s_) || since_s < departure_s_) departure_s_ = since_s;
  };
  Eigen::VectorXd offset = Eigen::VectorXd::Zero(m), offset_sigma = offset;
  if (offsets_ >= 0) {
    const Eigen::Index o = r_ + offsets_;
    offset = x_.segment(o, m);
    offset_sigma = p_.diagonal().segment(o, m).cwiseMax(0.0).cwiseSqrt();
    // An offset that appears after the first consistency window was not there from the start:
    // the sensor may have failed, or the machine changed beside it (heat near one sensor is
    // followed by its offset state and leaves the innovations consistent); the filter cannot
    // tell, so it also says recalibrate, dated from the offset's crossing.
    for (const HeldSensor& f : faults_.add(t, offset, offset_sigma))
      if (f.since_s > setup_.consistency.window_s) earliest(f.since_s);
  }
  if (setup_.consistency.model_residual_sigmas > 0) {
    // Each reading against the declared model's own run, less the sensor's estimated offset; a
    // sensor whose offset is beyond its fault bound is left out (NaN: not beyond).
    const double fault = setup_.consistency.sensor_fault_sigmas;
    Eigen::VectorXd residual = readings - setup_.sensor_rows * z_open_ - offset;
    for (Eigen::Index k = 0; k < m; ++k)
      if (fault > 0 && std::abs(offset(k)) > fault * offset_sigma(k))
        residual(k) = std::numeric_limits<double>::quiet_NaN();
    for (const HeldSensor& d : departures_.add(t, residual, setup_.noise.sensor_sigma_k))
      earliest(d.onset_s);
    e.sigma_terms.departure = residual.cwiseQuotient(setup_.noise.sensor_sigma_k);
    e.sigma_terms.evidence = evidence_.add(t, e.sigma_terms.departure);
  }
  if (!std::isnan(departure_s_)) {
    e.recalibrate_since_s =
        e.recalibrate ? std::min(e.recalibrate_since_s, departure_s_) : departure_s_;
    e.recalibrate = true;
  }
}

Eigen::VectorXd ExponentialMean::add(double t, const Eigen::VectorXd& value) {
  if (mean_.size() != value.size())
    mean_ = last_t_ = Eigen::VectorXd::Constant(value.size(), std::nan(""));
  Eigen::VectorXd out = value;
  for (Eigen::Index k = 0; k < value.size(); ++k) {
    if (std::isnan(value(k))) continue;
    if (std::isnan(mean_(k)) || !(tau_s_ > 0))
      mean_(k) = value(k);
    else
      mean_(k) += (1.0 - std::exp(-(t - last_t_(k)) / tau_s_)) * (value(k) - mean_(k));
    last_t_(k) = t;
    out(k) = mean_(k);
  }
  return out;
}

double departure_evidence(const Eigen::VectorXd& residual, const Eigen::VectorXd& sigma,
                          double onset, double bound) {
  double largest = 0;
  for (Eigen::Index k = 0; k < residual.size(); ++k)
    if (std::isfinite(residual(k))) largest = std::max(largest, std::abs(residual(k)) / sigma(k));
  if (bound <= onset) return largest > bound ? 1 : 0;
  return std::clamp((largest - onset) / (bound - onset), 0.0, 1.0);
}

double EvidenceMean::add(double t, const Eigen::VectorXd& departure) {
  return departure_evidence(mean_.add(t, departure), Eigen::VectorXd::Ones(departure.size()),
                            settings_.onset_sigmas, settings_.bound_sigmas);
}

Eigen::VectorXd evidence_of(const ObserverRun& run, const EvidenceSettings& settings) {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(run.sigma_terms.size()));
  EvidenceMean evidence(settings);
  for (std::size_t i = 0; i < run.sigma_terms.size(); ++i) {
    const Eigen::VectorXd& z = run.sigma_terms[i].departure;
    const auto k = static_cast<Eigen::Index>(i);
    if (z.size() != 0) out(k) = evidence.add(run.times(k), z);
  }
  return out;
}

DriftSigmaTerms KalmanObserver::drift_sigma_terms(const Eigen::VectorXd& drift) const {
  const Eigen::MatrixXd& l = setup_.target_rows;
  const ObserverNoise& n = setup_.noise;
  DriftSigmaTerms terms;
  Eigen::ArrayXd var = (l.lazyProduct(p_.topLeftCorner(r_, r_)).lazyProduct(l.transpose()))
                           .diagonal()
                           .cwiseMax(0.0)
                           .array() +
                       (n.drift_relative_sigma * drift.array()).square();
  if (n.drift_sigma_scale.size() != 0) var *= n.drift_sigma_scale.array().square();
  terms.model = var.sqrt().matrix();
  terms.correction = l.lazyProduct(x_.head(r_) - z_open_);
  const Eigen::VectorXd dz = x_.head(r_) - z0_;  // the states' change: the drift's, per material
  for (const Eigen::MatrixXd& rows : setup_.target_expansion)
    terms.expansion.push_back(rows.lazyProduct(dz));
  return terms;
}

double changed_terms_weight(const DriftSigmaTerms& terms, ChangedTermsGate gate) {
  if (gate == ChangedTermsGate::always || terms.alarm) return 1;
  return gate == ChangedTermsGate::on_evidence ? terms.evidence : 0;
}

Eigen::VectorXd drift_sigma(const DriftSigmaTerms& terms, double correction,
                            const Eigen::VectorXd& expansion, ChangedTermsGate gate) {
  Eigen::ArrayXd var = terms.model.array().square();
  const double w = changed_terms_weight(terms, gate);
  if (w <= 0) return terms.widening * var.sqrt().matrix();
  if (correction > 0) var += (w * correction * terms.correction.array()).square();
  for (Eigen::Index m = 0; m < expansion.size(); ++m)
    if (expansion(m) > 0)
      var += (w * expansion(m) * terms.expansion[static_cast<std::size_t>(m)].array()).square();
  return terms.widening * var.sqrt().matrix();
}

CovarianceMap KalmanObserver::advance(double t) {
  const Eigen::Index n = r_ + nb_;
  CovarianceMap map{Eigen::MatrixXd::Identity(n, n), Eigen::MatrixXd::Zero(n, n)};
  map_ = &map;
  try {
    advance_to(t);
  } catch (...) {
    map_ = nullptr;
    throw;
  }
  map_ = nullptr;
  return map;
}

ObserverSetup probed_setup(const ObserverSetup& setup) {
  ObserverSetup s = setup;
  if (s.noise.probed_drift_sigma_scale.size() != 0)
    s.noise.drift_sigma_scale = s.noise.probed_drift_sigma_scale;
  return s;
}

bool ProbeCycle::due(double t) {
  if (t + 1e-9 < next_) return false;
  while (next_ <= t + 1e-9) next_ += every_s_;
  return true;
}

DriftReadingTest::DriftReadingTest(const ReducedThermalSystem& system, const core::CaseSpec& spec,
                                   const ObserverSetup& setup)
    : blind_(system, spec, setup),
      held_(setup.consistency.model_residual_sigmas, setup.consistency.sustain_s, false),
      reading_sigma_m_(setup.noise.drift_reading_sigma_m),
      on_(setup.consistency.model_residual_sigmas > 0) {}

double DriftReadingTest::add(double t, const Eigen::VectorXd& readings,
                             const Eigen::VectorXd& drift) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!on_) return nan;  // no test: the temperature-only filter is not stepped
  const ObserverEstimate e = blind_.assimilate(t, readings);
  if (drift.size() == 0 || !drift.array().isFinite().any()) return nan;
  Eigen::VectorXd z = Eigen::VectorXd::Constant(drift.size(), nan);
  for (Eigen::Index j = 0; j < drift.size(); ++j)
    if (std::isfinite(drift(j)))
      z(j) = (drift(j) - e.drift(j)) /
             std::sqrt(e.drift_sigma(j) * e.drift_sigma(j) + reading_sigma_m_ * reading_sigma_m_);
  double since = nan;
  for (const HeldSensor& h : held_.add(t, z, Eigen::VectorXd::Ones(drift.size())))
    if (std::isnan(since) || h.since_s < since) since = h.since_s;
  return since;
}

namespace {

/// `run`'s record of sample i: the estimate, the filter's state and its unknown inputs.
void record(const KalmanObserver& kf, const ObserverEstimate& e, Eigen::Index i, ObserverRun& run) {
  if (e.drift_innovation.size() != 0) {
    if (run.drift_innovation.size() == 0) {
      run.drift_innovation.resize(run.drift.rows(), run.drift.cols());
      run.drift_innovation_sigma.resize(run.drift.rows(), run.drift.cols());
    }
    run.drift_innovation.row(i) = e.drift_innovation.transpose();
    run.drift_innovation_sigma.row(i) = e.drift_innovation_sigma.transpose();
  }
  const auto nb = static_cast<Eigen::Index>(kf.unknown_inputs().size());
  run.drift.row(i) = e.drift.transpose();
  run.drift_sigma.row(i) = e.drift_sigma.transpose();
  run.sigma_terms[static_cast<std::size_t>(i)] = e.sigma_terms;
  run.innovation.row(i) = e.innovation.transpose();
  run.nis(i) = e.nis;
  run.dof(i) = e.dof;
  run.window_nis(i) = kf.monitor().window_nis();
  run.window_bound(i) = kf.monitor().window_bound();
  run.states.col(i) = kf.state().head(kf.states());
  run.unknown_inputs.row(i) = kf.state().tail(nb).transpose();
  run.unknown_inputs_sigma.row(i) =
      kf.covariance().bottomRightCorner(nb, nb).diagonal().cwiseMax(0.0).cwiseSqrt().transpose();
}

}  // namespace

ObserverRun observe(const ReducedThermalSystem& system, const core::CaseSpec& spec,
                    const ObserverSetup& setup, const Eigen::VectorXd& times,
                    const Eigen::MatrixXd& readings, const Eigen::MatrixXd& drift_readings) {
  if (readings.rows() != times.size() ||
      (drift_readings.size() != 0 && drift_readings.rows() != times.size()))
    throw core::SolverError("observer: " + std::to_string(readings.rows()) +
                            " rows of readings and " + std::to_string(drift_readings.rows()) +
                            " of drift readings for " + std::to_string(times.size()) + " times");
  KalmanObserver kf(system, spec, drift_readings.size() != 0 ? probed_setup(setup) : setup);
  const Eigen::Index n = times.size(), nt = setup.target_rows.rows();
  const Eigen::Index nb = static_cast<Eigen::Index>(kf.unknown_inputs().size());
  ObserverRun run;
  run.times = times;
  run.drift.resize(n, nt);
  run.drift_sigma.resize(n, nt);
  run.sigma_terms.resize(static_cast<std::size_t>(n));
  run.innovation.resize(n, readings.cols());
  run.nis.resize(n);
  run.window_nis.resize(n);
  run.window_bound.resize(n);
  run.dof.resize(n);
  run.states.resize(kf.states(), n);
  run.unknown_inputs.resize(n, nb);
  run.unknown_inputs_sigma.resize(n, nb);
  run.unknown_input_names = kf.unknown_inputs();
  run.unknown_input_kinds = kf.unknown_input_kinds();
  std::optional<DriftReadingTest> test;
  if (drift_readings.size() != 0) test.emplace(system, spec, setup);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::VectorXd y = readings.row(i).transpose();
    const Eigen::VectorXd d =
        test ? Eigen::VectorXd(drift_readings.row(i).transpose()) : Eigen::VectorXd();
    const ObserverEstimate e = kf.assimilate(times(i), y, d);
    record(kf, e, i, run);
    if (e.recalibrate && !run.recalibrate) {
      run.recalibrate = true;
      run.recalibrate_since_s = e.recalibrate_since_s;
      run.recalibrate_at_s = e.time;
    }
    if (const double since = test ? test->add(times(i), y, d) : std::nan(""); !std::isnan(since)) {
      run.recalibrate_since_s = run.recalibrate ? std::min(run.recalibrate_since_s, since) : since;
      if (!run.recalibrate) run.recalibrate_at_s = times(i);
      run.recalibrate = true;
    }
  }
  if (n > 0) {
    run.sensor_faults = kf.sensor_faults();
    run.model_departures = kf.model_departures();
    if (test) run.drift_departures = test->raised();
  }
  return run;
}

namespace {

/// Per target, the (estimate - truth, reported sigma) of every sample whose truth is known and
/// whose sigma is above 0 (t = 0: the start is known). Throws SolverError when the sizes differ.
std::vector<std::vector<std::pair<double, double>>> errors_and_sigmas(
    const std::vector<ObserverRun>& runs, const std::vector<Eigen::MatrixXd>& truths) {
  if (runs.size() != truths.size() || runs.empty())
    throw core::SolverError("observer calibration: " + std::to_string(runs.size()) + " runs and " +
                            std::to_string(truths.size()) +
                            " truths; expected as many, at least 1");
  const Eigen::Index nt = runs.front().drift.cols();
  std::vector<std::vector<std::pair<double, double>>> out(static_cast<std::size_t>(nt));
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const ObserverRun& run = runs[k];
    const Eigen::MatrixXd& truth = truths[k];
    if (truth.rows() != run.drift.rows() || truth.cols() != nt || run.drift.cols() != nt)
      throw core::SolverError(
          "observer calibration: run " + std::to_string(k) + " has " +
          std::to_string(run.drift.rows()) + " x " + std::to_string(run.drift.cols()) +
          " estimates and " + std::to_string(truth.rows()) + " x " + std::to_string(truth.cols()) +
          " truths; expected " + std::to_string(nt) + " targets each and as many samples");
    for (Eigen::Index i = 0; i < truth.rows(); ++i)
      for (Eigen::Index t = 0; t < nt; ++t) {
        const double sigma = run.drift_sigma(i, t), e = run.drift(i, t) - truth(i, t);
        if (sigma > 0 && std::isfinite(e)) out[static_cast<std::size_t>(t)].emplace_back(e, sigma);
      }
  }
  return out;
}

/// The least factor f on sigma whose band ±2 sqrt((f sigma)^2 + noise^2) holds the error e.
double band_factor(double e, double sigma, double noise) {
  return std::sqrt(std::max(0.0, e * e / 4 - noise * noise)) / sigma;
}

}  // namespace

Eigen::VectorXd mean_normalised_squared_error(const std::vector<ObserverRun>& runs,
                                              const std::vector<Eigen::MatrixXd>& truths,
                                              double truth_sigma_m) {
  const auto samples = errors_and_sigmas(runs, truths);
  const auto nt = static_cast<Eigen::Index>(samples.size());
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(nt), count = Eigen::VectorXd::Zero(nt);
  const double truth_var = truth_sigma_m * truth_sigma_m;
  for (Eigen::Index t = 0; t < nt; ++t)
    for (const auto& [e, sigma] : samples[static_cast<std::size_t>(t)]) {
      sum(t) += (e * e - truth_var) / (sigma * sigma);
      count(t) += 1;
    }
  return (count.array() > 0)
      .select(sum.array() / count.array(), std::numeric_limits<double>::quiet_NaN())
      .matrix();
}

Eigen::VectorXd drift_sigma_calibration(const std::vector<ObserverRun>& runs,
                                        const std::vector<Eigen::MatrixXd>& truths,
                                        double truth_sigma_m,
                                        const Eigen::VectorXd& observed_with) {
  const Eigen::VectorXd nees = mean_normalised_squared_error(runs, truths, truth_sigma_m);
  if (observed_with.size() != 0 && observed_with.size() != nees.size())
    throw core::SolverError("observer calibration: " + std::to_string(observed_with.size()) +
                            " scales for " + std::to_string(nees.size()) + " targets");
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(nees.size());
  for (Eigen::Index t = 0; t < nees.size(); ++t) {
    if (nees(t) > 0) scale(t) = std::sqrt(nees(t));  // NaN and <= 0 (noise only) keep 1
    if (observed_with.size() != 0) scale(t) *= observed_with(t);
  }
  return scale;
}

DriftBandScore drift_band_score(const std::vector<ObserverRun>& runs,
                                const std::vector<Eigen::MatrixXd>& truths,
                                const Eigen::VectorXd& factor, double truth_sigma_m) {
  const auto samples = errors_and_sigmas(runs, truths);
  const auto nt = static_cast<Eigen::Index>(samples.size());
  if (factor.size() != 0 && factor.size() != nt)
    throw core::SolverError("observer score: " + std::to_string(factor.size()) + " factors for " +
                            std::to_string(nt) + " targets");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  DriftBandScore score{Eigen::VectorXi::Zero(nt), Eigen::VectorXd::Constant(nt, nan),
                       Eigen::VectorXd::Constant(nt, nan), Eigen::VectorXd::Constant(nt, nan)};
  for (Eigen::Index t = 0; t < nt; ++t) {
    const auto& st = samples[static_cast<std::size_t>(t)];
    if (st.empty()) continue;
    const double f = factor.size() != 0 ? factor(t) : 1.0;
    double squares = 0, sigma_squares = 0, inside = 0;
    for (const auto& [e, sigma] : st) {
      squares += e * e;
      sigma_squares += f * f * sigma * sigma;
      inside += band_factor(e, sigma, truth_sigma_m) <= f;
    }
    const auto n = static_cast<double>(st.size());
    score.samples(t) = static_cast<int>(st.size());
    score.rms_error_m(t) = std::sqrt(squares / n);
    score.rms_sigma_m(t) = std::sqrt(sigma_squares / n);
    score.coverage(t) = inside / n;
  }
  return score;
}

Eigen::VectorXd drift_sigma_coverage_calibration(const std::vector<ObserverRun>& runs,
                                                 const std::vector<Eigen::MatrixXd>& truths,
                                                 double coverage,
                                                 const Eigen::VectorXd& observed_with) {
  if (!(coverage > 0 && coverage < 1))
    throw core::SolverError("observer calibration: coverage " + number(coverage) +
                            ": expected 0 < coverage < 1");
  const auto samples = errors_and_sigmas(runs, truths);
  const auto nt = static_cast<Eigen::Index>(samples.size());
  if (observed_with.size() != 0 && observed_with.size() != nt)
    throw core::SolverError("observer calibration: " + std::to_string(observed_with.size()) +
                            " scales for " + std::to_string(nt) + " targets");
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(nt);
  for (Eigen::Index t = 0; t < nt; ++t) {
    std::vector<double> ratio;
    for (const auto& [e, sigma] : samples[static_cast<std::size_t>(t)])
      ratio.push_back(band_factor(e, sigma, 0));
    if (!ratio.empty()) {
      // The nearest rank: the smallest factor under which at least `coverage` of them lie.
      const auto rank = static_cast<std::size_t>(
          std::max(1.0, std::ceil(coverage * static_cast<double>(ratio.size()) - 1e-9)) - 1);
      std::nth_element(ratio.begin(), ratio.begin() + static_cast<std::ptrdiff_t>(rank),
                       ratio.end());
      if (ratio[rank] > 0) scale(t) = ratio[rank];
    }
    if (observed_with.size() != 0) scale(t) *= observed_with(t);
  }
  return scale;
}

}  // namespace tt::solvers
