// A physics observer beside the machine: a Kalman filter on the reduced-order twin's states that
// takes the duty cycle's inputs (the case's loads, stepped by the twin's own stepper) and the
// placed sensors' readings together, and predicts the thermal drift at the tool (and the axis
// points) with its standard deviation. Its innovations (readings minus predicted readings) are
// tested for consistency with the noise model: a sustained inconsistency says the machine is no
// longer the model (recalibrate). docs/observer.md gives the model, its noise and the figures.
//
// State: x = [z; b], z the reduced thermal state (T = V z), b unknown inputs the case does not
// declare, each a random walk: one heat input per fixed heat source (power added to its shape)
// and per convection entry (spread over its surface, by area), and one air-temperature offset of
// the sinks of the chosen convection entries; optionally one offset per sensor, which enters that
// sensor's reading only (ObserverNoise::sensor_offset_initial_k). One step of the case's grid:
//   z1 = Phi z0 + u + Gamma b0,  b1 = b0 + w,  w ~ N(0, diag(q) dt),
// Phi and u the stepper's affine map (ReducedStepper), Gamma = (C + theta dt A)^{-1} dt B(h) with
// B the unknown inputs' columns (the air's column is sum_c h_c(speed) a_c: it follows the film).
// Readings y = H z + o + v, H the sensors' rows on the reduced state, o the offsets (0 without
// them), v ~ N(0, diag(sigma^2)). A drift reading (a probe cycle measuring the tool, when there is
// one) d = L (z - z(0)) + v_d, L the target's drift row: it enters the filter and its NIS the same
// way, and sees what no temperature shows (a wrong expansion coefficient).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "solvers/thermal_stepper.hpp"
#include "solvers/thermal_system.hpp"
#include "solvers/twin.hpp"

namespace tt::solvers {

/// When the drift sigma's terms for a changed machine (ObserverNoise::correction_relative_sigma
/// and expansion_relative_sigma) act. A change no reading shows (a wrong expansion coefficient
/// without a probe cycle) raises no evidence and no alarm: only `always` covers it.
enum class ChangedTermsGate {
  always,  /// on every sample: wide on a machine that has not changed
  /// Before the alarm, weighted by the evidence that the machine is departing from the declared
  /// model (DriftSigmaTerms::evidence: 0 while every reading is within the departure test's
  /// onset bound of the declared model's run, 1 at its alarm bound); fully from the alarm on.
  on_evidence,
  /// Only from the sample at which the filter says recalibrate (its NIS test, a model departure,
  /// a late offset): the band stays as calibrated until the filter sees the change.
  after_alarm,
};

/// Every gate, in the order sigma_calibration.json's changed_machine.gates lists them.
inline constexpr ChangedTermsGate kChangedTermsGates[] = {
    ChangedTermsGate::always, ChangedTermsGate::on_evidence, ChangedTermsGate::after_alarm};

/// What the observer does not know, and how sure it is of the rest.
struct ObserverNoise {
  /// Per sensor: standard deviation of a reading's white noise [K] (#sensors).
  Eigen::VectorXd sensor_sigma_k;
  /// Random walk of each unknown heat input [W per sqrt(h)], and its spread at t = 0 [W].
  double heat_walk_w = 4.0, heat_initial_w = 2.0;
  /// Random walk of the air-temperature offset [K per sqrt(h)], and its spread at t = 0 [K].
  double air_walk_k = 0.5, air_initial_k = 0.3;
  /// Per sensor an offset of its reading, an unknown input of its own that enters that sensor's
  /// reading only (y = H z + o + v): an installation error or a fault (a sensor off by a constant,
  /// or slowly wandering, amount) is then estimated as an offset instead of being read as heat.
  /// Its spread at t = 0 [K] and its random walk [K per sqrt(h)]; both 0 (the library's default):
  /// no offset states. The known initial field is what tells an offset (there from the first
  /// reading) from heat (which takes time to warm a sensor).
  double sensor_offset_initial_k = 0, sensor_offset_walk_k = 0;
  /// White process noise on every reduced state [K per sqrt(h)] in the capacity norm: model-form
  /// error that no input explains (0: none).
  double state_walk_k = 0;
  /// Error of the drift rows themselves (the elastic model's discretisation, its material
  /// values), relative to the predicted drift [-]: added to the drift's variance as (e d)^2.
  double drift_relative_sigma = 0;
  /// Error of the drift that the filter's corrections account for, relative to it [-]. The
  /// correction d_c = L (z - z_open) is how far the estimated unknown inputs and the readings have
  /// moved the drift from the declared model's own run (z_open: the same steps with no unknown
  /// input and no reading). It rests on the unknown inputs' assumed shapes (heat on a source's
  /// shape or spread over a film's surface, the air on the sinks), which an undeclared effect
  /// need not have: added to the drift's variance as (c d_c)^2, after drift_sigma_scale (which is
  /// calibrated where the declared model holds and the corrections are small) and before the
  /// widening. 0: none. (z_open takes each step's affine map as the
  /// filter does, at the filtered state: the same map unless the case's heat depends on
  /// temperature.)
  double correction_relative_sigma = 0;
  /// Per material (ObserverSetup::target_expansion's order): the error of its expansion
  /// coefficient, relative to its declared value, the materials independent of each other [-]:
  /// added to the drift's variance as the sum over the materials of (e_m d_m)^2, d_m the part of
  /// the drift that material m's thermal strain makes (a wrong expansion coefficient changes no
  /// temperature, so no reading and no other term sees it). After drift_sigma_scale, like the
  /// correction's, and before the widening. Empty (or zeros): none.
  Eigen::VectorXd expansion_relative_sigma;
  /// Per target: a factor on the reported standard deviation of the drift, calibrated on runs
  /// whose drift is known (drift_sigma_calibration); it leaves the filter (gain, innovations,
  /// alarm) as it is. Empty: 1 for every target.
  Eigen::VectorXd drift_sigma_scale;
  /// Per target: the factor on the reported sigma of a filter that assimilates drift readings (a
  /// probe cycle), calibrated on runs observed with it: the readings narrow the posterior, so
  /// drift_sigma_scale, calibrated on temperatures alone, would cover too little. The drift test's
  /// temperature-only filter keeps drift_sigma_scale. Empty: drift_sigma_scale.
  Eigen::VectorXd probed_drift_sigma_scale;
  /// Standard deviation of a drift reading's white noise [m] (a probe cycle measuring the tool's
  /// drift, KalmanObserver::assimilate's drift_readings); the drift rows' relative error
  /// (drift_relative_sigma) is added to it at the predicted drift.
  double drift_reading_sigma_m = 0.3e-6;
  /// Widen the reported sigma while the innovations say the machine is no longer the model: by
  /// sqrt(NIS / dof) over the consistency window when that is above 1 (a filter whose noise is
  /// too small by a factor a has innovations a times its S, and errors a times its P). It leaves
  /// the filter (gain, innovations, alarm) as it is, like drift_sigma_scale, on top of which it
  /// acts: a sigma calibrated where the model holds does not stay narrow where it no longer does.
  bool widen_on_inconsistency = false;
  /// When the correction's and the expansion's terms (correction_relative_sigma,
  /// expansion_relative_sigma) act (ChangedTermsGate).
  ChangedTermsGate changed_terms = ChangedTermsGate::always;
};

/// The consistency test of the innovations: the normalised innovation squared (NIS, nu^T S^-1 nu,
/// chi-square with #readings degrees of freedom when the model holds) summed over a sliding
/// window is compared with the chi-square quantile `probability` of the window's degrees of
/// freedom; an exceedance held for `sustain_s` raises `recalibrate`, dated from the change point
/// of the NIS's mean before it (InnovationMonitor::since_s).
struct ConsistencyOptions {
  double window_s = 1800;
  double probability = 0.999;
  double sustain_s = 900;
  /// The sensors' offsets (ObserverNoise::sensor_offset_initial_k): a sensor whose estimated
  /// offset stays beyond this many of its standard deviations for `sustain_s` is reported faulty
  /// (HeldBeyondMonitor); 0: no such test. Under the noise model an offset's estimate is beyond
  /// 4 sigma with probability 6e-5 (two-sided), and the test asks it to stay there. A fault
  /// whose offset crossed the bound after the first window (`window_s`) was not there from the
  /// start, and heat near that one sensor looks the same: it raises recalibrate as well.
  double sensor_fault_sigmas = 4;
  /// The declared model's own run (the case's inputs stepped with no unknown input and no
  /// reading) against the readings: a sensor whose reading stays more than this many of its
  /// sigmas (ObserverNoise::sensor_sigma_k) from it for `sustain_s` says the machine is no longer
  /// the declared one, and raises recalibrate (dated as departure_onset_sigmas says). The
  /// unknown inputs follow heat, air and films that the case does not declare, so their
  /// innovations stay consistent and the NIS test alone sees none of them; the declared model's
  /// run does not follow them. With offset states the sensor's estimated offset is taken off its
  /// reading, and a sensor whose offset is beyond its fault bound is left out (its own fault,
  /// not the machine's). 0: no such test.
  double model_residual_sigmas = 3;
  /// That test's alarm is dated from each departing sensor's onset (HeldSensor::onset_s): the
  /// last time before it crossed that its reading was within this many sigmas of the declared
  /// run. A change that grows from its start crosses 3 sigma hours after it began; the readings
  /// of a clean run are within 1 sigma 68 % of the time. 0: dated from the crossing.
  double departure_onset_sigmas = 1;
  /// The evidence of a change (DriftSigmaTerms::evidence) is taken of each sensor's residual
  /// against the declared run averaged with this time constant [s] (ExponentialMean), so that a
  /// reading's noise does not make it: the departure test holds its bound for sustain_s instead,
  /// the evidence has no hold. 0: of the residual itself.
  double evidence_time_s = 300;
  /// The evidence is 0 while every sensor's mean is within this many of its sigmas and 1 at
  /// model_residual_sigmas (departure_evidence's onset; the alarm's dating keeps
  /// departure_onset_sigmas).
  double evidence_onset_sigmas = 1;
};

/// The observer's set-up on a reduced system.
struct ObserverSetup {
  Eigen::MatrixXd sensor_rows;            /// #sensors x r: reading [K] = row z
  Eigen::MatrixXd target_rows;            /// #targets x r: drift [m] = row (z - z(0))
  std::vector<std::string> target_names;  /// e.g. "dx", "dy", "dz", "<axis point>_dx"
  /// Per material: the part of target_rows its thermal strain makes (#targets x r each, summing to
  /// target_rows), and the materials' names; needed for noise.expansion_relative_sigma.
  std::vector<Eigen::MatrixXd> target_expansion;
  std::vector<std::string> expansion_materials;
  std::vector<int> air_entries;           /// convection entries whose sink the air offset moves
  std::vector<std::string> sensor_names;  /// the sensors' ids (the offsets' names); empty: indices
  double initial_temperature_k = std::numeric_limits<double>::quiet_NaN();  /// NaN: the case's
  ObserverNoise noise;
  ConsistencyOptions consistency;
};

/// The set-up on a twin: the named points `sensors` (ids) read with `noise`, the TCP's drift
/// (dx, dy, dz) and every axis point's as targets, the air offset on air_entries(spec). With
/// `sensor_rows` (#sensors x the twin's states: sensors read elsewhere than at a named point, e.g.
/// twin_point_row), the sensors are read through those rows and `sensors` only names them. Throws
/// SolverError naming an id that is not a named point of the twin (without rows), rows of another
/// shape, or a twin without TCP rows.
ObserverSetup twin_observer_setup(const Twin& twin, const core::CaseSpec& spec,
                                  const std::vector<std::string>& sensors,
                                  const ObserverNoise& noise,
                                  const Eigen::MatrixXd& sensor_rows = Eigen::MatrixXd());

/// The twin's temperature row at a point given by interpolation weights over mesh nodes
/// ((node, weight) pairs): sum of weight x the basis's row of the node. Throws SolverError for a
/// node outside the basis.
Eigen::RowVectorXd twin_point_row(const Twin& twin,
                                  const std::vector<std::pair<int, double>>& weights);

/// Convection entries of `spec` that are not on a mechanically fixed group (the shop's air; the
/// bed contact's sink is the foundation): the calibration generator's air acts on these.
std::vector<int> air_entries(const core::CaseSpec& spec);

/// Quantile p of the chi-square distribution with k > 0 degrees of freedom (Wilson–Hilferty;
/// relative error below 1 % for k >= 3 at p <= 0.999).
double chi_square_quantile(double p, double k);

/// The sliding-window test of ConsistencyOptions, fed one assimilation at a time.
class InnovationMonitor {
 public:
  explicit InnovationMonitor(const ConsistencyOptions& options) : o_(options) {}
  /// Adds the NIS of an assimilation at time t with `dof` readings; returns whether the status is
  /// now (and stays) `recalibrate`.
  bool add(double t, double nis, int dof);
  double window_nis() const { return sum_; }      /// NIS summed over the window
  double window_bound() const { return bound_; }  /// its chi-square bound
  int window_dof() const { return dof_sum_; }     /// readings in the window: NIS's expectation
  bool exceeded() const { return sum_ > bound_; }
  bool recalibrate() const { return alarm_; }
  /// When the inconsistency started [s]: the change point of the NIS's mean before the alarm,
  /// the sample after the lowest point of the cumulative sum of NIS - dof (a CUSUM).
  double since_s() const { return alarm_start_; }

 private:
  double change_start() const;
  ConsistencyOptions o_;
  std::vector<double> t_, nis_;
  std::vector<int> dof_;
  std::size_t first_ = 0;
  double sum_ = 0, bound_ = std::numeric_limits<double>::infinity();
  int dof_sum_ = 0;
  double exceed_start_ = std::numeric_limits<double>::quiet_NaN();
  double alarm_start_ = std::numeric_limits<double>::quiet_NaN();
  bool alarm_ = false;
};

/// A sensor whose value (its offset state, or its reading's distance from the declared model's
/// run) was held beyond a bound (HeldBeyondMonitor): a sensor fault, or the machine's departure.
struct HeldSensor {
  int sensor = 0;                                              /// index into the setup's sensors
  double since_s = std::numeric_limits<double>::quiet_NaN();   /// first beyond the bound
  double raised_s = std::numeric_limits<double>::quiet_NaN();  /// held for sustain_s: raised
  /// The last time at or before since_s that the value was within the monitor's onset bound
  /// (where a change that grows from there began, as near as the values tell); its first time
  /// when it never was; since_s when the monitor has no onset bound.
  double onset_s = std::numeric_limits<double>::quiet_NaN();
};

/// A per-sensor value held beyond a bound, fed one assimilation at a time: sensor k is raised
/// once |value_k| > sigmas * sigma_k has held for sustain_s (a NaN value is not beyond); a raised
/// sensor stays raised. `exclusive` (the offsets' fault test): only as the only sensor not yet
/// raised beyond the bound (several together are heat or air read as offsets, likelier than
/// several sensors failing at once: their clocks restart). `onset_sigmas` > 0: each raised
/// sensor's onset_s walks back from since_s to the last time |value_k| <= onset_sigmas * sigma_k.
class HeldBeyondMonitor {
 public:
  HeldBeyondMonitor(double sigmas, double sustain_s, bool exclusive = true, double onset_sigmas = 0)
      : sigmas_(sigmas),
        sustain_s_(sustain_s),
        onset_sigmas_(onset_sigmas),
        exclusive_(exclusive) {}
  /// The values and their standard deviations at time t, one per sensor; returns the sensors
  /// raised at t (also appended to raised()).
  std::vector<HeldSensor> add(double t, const Eigen::Ref<const Eigen::VectorXd>& value,
                              const Eigen::Ref<const Eigen::VectorXd>& sigma);
  /// The sensors raised so far, in the order they were raised.
  const std::vector<HeldSensor>& raised() const { return held_; }

 private:
  double sigmas_, sustain_s_, onset_sigmas_;
  bool exclusive_;
  std::vector<double> beyond_since_;  /// per sensor: NaN while within the bound
  /// per sensor: the last time within the onset bound (the first time seen until it is)
  std::vector<double> within_onset_;
  std::vector<bool> raised_;
  std::vector<HeldSensor> held_;
};

/// Per sensor an exponentially weighted mean of a value fed one assimilation at a time, with time
/// constant tau_s: mean += (1 - exp(-dt / tau_s)) (value - mean), dt since that sensor's last
/// value. Its first value starts it; a NaN value leaves its mean as it was and reads NaN at that
/// time; tau_s 0: the value itself.
class ExponentialMean {
 public:
  explicit ExponentialMean(double tau_s) : tau_s_(tau_s) {}
  /// The values at time t (after the last); returns the means at t.
  Eigen::VectorXd add(double t, const Eigen::VectorXd& value);

 private:
  double tau_s_;
  Eigen::VectorXd mean_, last_t_;  /// per sensor (NaN: no value yet)
};

/// The terms of the reported drift sigma at one time (docs/observer.md, "Drift"): sigma^2 =
/// widening^2 (model^2 + (c correction)^2 + sum over materials m of (e_m expansion_m)^2), c the
/// noise's correction_relative_sigma and e its expansion_relative_sigma. Kept per sample
/// (ObserverRun::sigma_terms), so that other c and e are scored without observing again: the
/// estimate does not depend on them.
struct DriftSigmaTerms {
  /// #targets: the estimate's and the drift rows' sigma, times drift_sigma_scale [m]
  Eigen::VectorXd model;
  Eigen::VectorXd correction;  /// #targets: d_c = L (z - z_open) [m]
  /// per material (ObserverSetup::target_expansion's order), #targets: the drift its thermal
  /// strain makes [m]
  std::vector<Eigen::VectorXd> expansion;
  double widening = 1;  /// the widening on inconsistency's factor, >= 1 (1: none)
  bool alarm = false;   /// the filter says recalibrate at this time
  /// In [0, 1]: how far the readings have departed from the declared model's own run, on the
  /// departure test's scale (ConsistencyOptions::model_residual_sigmas): (max over the sensors of
  /// |reading - declared run| / sigma_k - onset) / (bound - onset), clamped, the onset bound
  /// evidence_onset_sigmas and the bound model_residual_sigmas; the sensors the departure test
  /// leaves out (a faulty offset) are left out here too. 0 without that test.
  double evidence = 0;
  /// #sensors: the departure test's residual over each sensor's sigma, NaN where that test left
  /// the sensor out (empty without the test): what the evidence is made of, kept so that other
  /// evidence settings are scored without observing again (evidence_of).
  Eigen::VectorXd departure;
};

/// DriftSigmaTerms::evidence of the residuals (reading - declared run, per sensor; NaN: left
/// out) and their sigmas: the largest |residual| / sigma, from `onset` (0) to `bound` (1),
/// clamped (a step at `bound` when bound <= onset).
double departure_evidence(const Eigen::VectorXd& residual, const Eigen::VectorXd& sigma,
                          double onset, double bound);

/// How the evidence is taken of the departure test's residuals (ConsistencyOptions'
/// evidence_time_s and evidence_onset_sigmas, the bound its model_residual_sigmas).
struct EvidenceSettings {
  double time_s = 300, onset_sigmas = 1, bound_sigmas = 3;
};

/// The evidence settings of a consistency test's options.
inline EvidenceSettings evidence_settings(const ConsistencyOptions& c) {
  return {c.evidence_time_s, c.evidence_onset_sigmas, c.model_residual_sigmas};
}

/// The evidence sample by sample (DriftSigmaTerms::evidence): each sensor's departure (residual
/// over sigma; NaN: left out) averaged with settings.time_s (ExponentialMean), then
/// departure_evidence's ramp from settings.onset_sigmas to settings.bound_sigmas. The one way the
/// observer and evidence_of take it.
class EvidenceMean {
 public:
  explicit EvidenceMean(const EvidenceSettings& settings)
      : settings_(settings), mean_(settings.time_s) {}
  /// The departures at time t (after the last); returns the evidence at t.
  double add(double t, const Eigen::VectorXd& departure);

 private:
  EvidenceSettings settings_;
  ExponentialMean mean_;
};

/// The weight of the changed machine's terms in `terms` under `gate`: 1, the evidence or 0
/// before the alarm, 1 from it on.
double changed_terms_weight(const DriftSigmaTerms& terms, ChangedTermsGate gate);

/// The reported sigma (#targets [m]) of `terms` under a correction sigma c and, per material,
/// an expansion sigma (`expansion`: empty or one per material), both times the gate's weight
/// (changed_terms_weight).
Eigen::VectorXd drift_sigma(const DriftSigmaTerms& terms, double correction,
                            const Eigen::VectorXd& expansion,
                            ChangedTermsGate gate = ChangedTermsGate::always);

/// What the observer says after one assimilation.
struct ObserverEstimate {
  double time = 0;              /// [s]
  Eigen::VectorXd drift;        /// #targets [m], relative to t = 0
  Eigen::VectorXd drift_sigma;  /// #targets standard deviation [m]
  DriftSigmaTerms sigma_terms;  /// what drift_sigma is made of
  Eigen::VectorXd innovation;   /// #sensors reading minus prediction [K], NaN where missing
  /// #targets drift reading minus prediction [m], and its standard deviation under the noise
  /// model [m]; NaN where there is none (empty: no drift reading)
  Eigen::VectorXd drift_innovation, drift_innovation_sigma;
  double nis = 0;  /// normalised innovation squared
  int dof = 0;     /// readings used (temperatures and drifts)
  bool recalibrate = false;
  double recalibrate_since_s = std::numeric_limits<double>::quiet_NaN();
};

/// How the filter's covariance goes from one time to a later one with no reading between:
/// P(t1) = F P(t0) F^T + Q over the steps taken (F = the product of the steps' maps).
struct CovarianceMap {
  Eigen::MatrixXd transition;  /// (r + #unknown inputs) square: F
  Eigen::MatrixXd process;     /// the same size: Q [K^2, W^2, ...]
};

/// What an unknown input is: a heat input [W], the air's offset [K] or a sensor's offset [K].
enum class UnknownInputKind { heat, air, sensor_offset };

/// The filter. Steps the case's loads (its duty cycle, feed axis, sinks and fluxes are its inputs)
/// in steps of at most the case's step, equal between the load's switches and the readings, and
/// assimilates readings as they come. It looks no further ahead than the next reading: the duty
/// cycle may grow as samples arrive (LiveObserver).
class KalmanObserver {
 public:
  /// `system` and `spec` must outlive the observer. Throws SolverError when the rows do not have r
  /// columns, the sensors' sigmas are not one positive value per sensor, or an air entry is not a
  /// convection entry of `spec`.
  KalmanObserver(const ReducedThermalSystem& system, const core::CaseSpec& spec,
                 const ObserverSetup& setup);
  /// Steps to time t (a step ends there) and assimilates `readings` (#sensors [K], NaN: missing)
  /// and, when given, `drift_readings` (#targets [m] relative to t = 0, NaN: none; a probe cycle
  /// measuring the tool now and then). Throws SolverError for t before the last assimilation or
  /// beyond the duty cycle's end, or readings of another size.
  ObserverEstimate assimilate(double t, const Eigen::VectorXd& readings,
                              const Eigen::VectorXd& drift_readings = Eigen::VectorXd());
  /// Steps to time t as assimilate does, without a reading, and returns the covariance's map over
  /// those steps: what a criterion on the covariance alone needs (it does not see the readings'
  /// values; placement for estimation). Throws as assimilate does.
  CovarianceMap advance(double t);

  const Eigen::VectorXd& state() const { return x_; }  /// [z; b]
  const Eigen::MatrixXd& covariance() const { return p_; }
  const std::vector<std::string>& unknown_inputs() const { return bias_names_; }
  /// Per unknown input, in the order of unknown_inputs(): heat inputs, then the air, then the
  /// sensors' offsets.
  std::vector<UnknownInputKind> unknown_input_kinds() const;
  Eigen::Index states() const { return r_; }
  const InnovationMonitor& monitor() const { return monitor_; }
  /// The sensors found faulty so far (an offset beyond ConsistencyOptions::sensor_fault_sigmas),
  /// in the order they were raised; empty without offset states.
  const std::vector<HeldSensor>& sensor_faults() const { return faults_.raised(); }
  /// The sensors whose readings stayed away from the declared model's own run
  /// (ConsistencyOptions::model_residual_sigmas), in the order they were raised.
  const std::vector<HeldSensor>& model_departures() const { return departures_.raised(); }

 private:
  void advance_to(double t);
  void step(double t1);
  void add_process_noise(Eigen::MatrixXd& p, double dt) const;
  /// The terms of the drift's standard deviation at the current estimate, `drift` = L (z - z(0)):
  /// the filter's and the drift rows' relative error times the scale, the correction, the
  /// materials' drifts (ObserverNoise); the widening is the caller's.
  DriftSigmaTerms drift_sigma_terms(const Eigen::VectorXd& drift) const;
  /// The tests beside the NIS's after an assimilation at t (the offsets' faults, the readings
  /// against the declared model's run): raises `e.recalibrate` where they say so.
  void test_departures(double t, const Eigen::VectorXd& readings, ObserverEstimate& e);
  /// The Kalman update with the readings and drift readings that are not NaN.
  void update(double t, const Eigen::VectorXd& readings, const Eigen::VectorXd& drift_readings,
              ObserverEstimate& e);

  const ReducedThermalSystem& sys_;
  const core::CaseSpec& spec_;
  ObserverSetup setup_;
  ReducedStepper stepper_;
  Eigen::Index r_ = 0, nb_ = 0;
  Eigen::MatrixXd heat_columns_;         /// r x #heat biases [state per W]
  std::vector<std::string> bias_names_;  /// heat:<source>, heat:<group>, air, offset:<sensor>
  Eigen::Index offsets_ = 0;             /// the sensor offsets' first index in b (-1: none)
  Eigen::VectorXd bias_walk_;            /// per bias: variance per second
  Eigen::VectorXd x_, z0_;
  Eigen::VectorXd z_open_;  /// the declared model's own run
  Eigen::MatrixXd p_;
  double t_ = 0, prev_speed_ = std::numeric_limits<double>::quiet_NaN();
  InnovationMonitor monitor_;
  HeldBeyondMonitor faults_, departures_;
  EvidenceMean evidence_;  /// the departure test's residuals over their sigmas, for the evidence
  /// The earliest start of what says recalibrate besides the NIS test [s] (NaN: none yet): a
  /// fault whose offset appeared after the first consistency window, or a reading held away
  /// from the declared model's run.
  double departure_s_ = std::numeric_limits<double>::quiet_NaN();
  CovarianceMap* map_ = nullptr;  /// while advance() runs: the steps' map, accumulated
};

/// A whole run through the observer: one assimilation per sample.
struct ObserverRun {
  Eigen::VectorXd times;                          /// #samples [s]
  Eigen::MatrixXd drift, drift_sigma;             /// #samples x #targets [m]
  Eigen::MatrixXd innovation;                     /// #samples x #sensors [K]
  Eigen::VectorXd nis, window_nis, window_bound;  /// #samples
  Eigen::VectorXi dof;                            /// #samples
  Eigen::MatrixXd states;                         /// r x #samples: the estimated reduced states
  Eigen::MatrixXd unknown_inputs, unknown_inputs_sigma;  /// #samples x #biases
  std::vector<std::string> unknown_input_names;
  std::vector<UnknownInputKind> unknown_input_kinds;  /// per bias, in the order of the names
  bool recalibrate = false;
  double recalibrate_since_s = std::numeric_limits<double>::quiet_NaN();  /// change point
  double recalibrate_at_s = std::numeric_limits<double>::quiet_NaN();     /// when it was raised
  std::vector<HeldSensor> sensor_faults;  /// raised over the run, in that order
  /// Readings held away from the declared model's run, in the order raised (the first says
  /// recalibrate; ConsistencyOptions::model_residual_sigmas).
  std::vector<HeldSensor> model_departures;
  /// Drift readings' innovations and their sigmas (#samples x #targets [m], NaN where none; empty
  /// without drift readings).
  Eigen::MatrixXd drift_innovation, drift_innovation_sigma;
  /// Targets whose drift readings departed from what the temperatures alone predict (observe's
  /// drift test; HeldSensor::sensor: the target's index), in the order raised; each says
  /// recalibrate.
  std::vector<HeldSensor> drift_departures;
  std::vector<DriftSigmaTerms> sigma_terms;  /// per sample: what drift_sigma is made of
};

/// The evidence at each of `run`'s samples (DriftSigmaTerms::departure, in order, at run.times)
/// under `settings`: what the observer would have said with them; the observer's own where they
/// are its own. Zeros where a sample kept no departure.
Eigen::VectorXd evidence_of(const ObserverRun& run, const EvidenceSettings& settings);

/// `setup` for a filter that assimilates drift readings: its reported sigma scaled by
/// noise.probed_drift_sigma_scale when that is set.
ObserverSetup probed_setup(const ObserverSetup& setup);

/// Which samples of a probe cycle read the tool's drift: the first at or after each multiple of
/// every_s (> 0), asked in increasing time.
class ProbeCycle {
 public:
  explicit ProbeCycle(double every_s) : every_s_(every_s), next_(every_s) {}
  /// Whether the sample at t reads the drift (and, if so, the next multiple after t is the next).
  bool due(double t);

 private:
  double every_s_, next_;
};

/// observe's drift test: a filter on the temperatures alone beside the one that assimilates the
/// drift readings, and each drift reading against its drift, in its reported sigma (with
/// drift_sigma_scale) and the reading's (drift_reading_sigma_m); a target held beyond
/// model_residual_sigmas over readings sustain_s apart is raised (HeldBeyondMonitor; never with
/// model_residual_sigmas 0). `system`, `spec` must outlive it.
class DriftReadingTest {
 public:
  DriftReadingTest(const ReducedThermalSystem& system, const core::CaseSpec& spec,
                   const ObserverSetup& setup);
  /// Steps the temperature-only filter to t with `readings` (#sensors [K], NaN: missing) and tests
  /// `drift` (#targets [m], NaN or empty: none); with model_residual_sigmas 0 it does neither.
  /// Returns the earliest start of a target raised now (NaN: none).
  double add(double t, const Eigen::VectorXd& readings, const Eigen::VectorXd& drift);
  const std::vector<HeldSensor>& raised() const { return held_.raised(); }

 private:
  KalmanObserver blind_;
  HeldBeyondMonitor held_;
  double reading_sigma_m_;
  bool on_;
};

/// `readings`: #samples x #sensors [K] at `times` (increasing, after 0, within the duty cycle);
/// `drift_readings`: none (empty) or #samples x #targets [m], NaN where a target is not read.
/// With drift readings the filter assimilates them, and a second filter on the temperatures alone
/// tests them: a target whose reading stays more than model_residual_sigmas from that filter's
/// drift (in its reported sigma, drift_sigma_scale and all, and the reading's) over readings
/// sustain_s apart has changed in a way no temperature shows (a wrong expansion coefficient):
/// recalibrate, dated from the first such reading.
ObserverRun observe(const ReducedThermalSystem& system, const core::CaseSpec& spec,
                    const ObserverSetup& setup, const Eigen::VectorXd& times,
                    const Eigen::MatrixXd& readings,
                    const Eigen::MatrixXd& drift_readings = Eigen::MatrixXd());

/// The mean normalised squared error of the reported drift per target over runs whose true drift
/// is known (training runs): mean over samples of ((estimate - truth)^2 - truth_sigma^2) / sigma^2,
/// 1 when the reported sigma is right, below 1 when it is too wide. `truths[k]`: #samples x
/// #targets [m] of runs[k]'s samples, NaN where a target's truth is not known; truth_sigma_m: the
/// white noise of a measured truth (probes), whose variance is taken out. Samples whose sigma is 0
/// (t = 0: the start is known) are left out. Throws SolverError when the sizes differ. #targets
/// (NaN where no sample counted).
Eigen::VectorXd mean_normalised_squared_error(const std::vector<ObserverRun>& runs,
                                              const std::vector<Eigen::MatrixXd>& truths,
                                              double truth_sigma_m = 0);

/// The factor on the reported sigma that makes the runs' mean normalised squared error 1: per
/// target sqrt(mean_normalised_squared_error) times the scale the runs were observed with
/// (`observed_with`, empty: 1); 1 where no sample counted or the error is not above the truth's
/// noise. For ObserverNoise::drift_sigma_scale.
Eigen::VectorXd drift_sigma_calibration(const std::vector<ObserverRun>& runs,
                                        const std::vector<Eigen::MatrixXd>& truths,
                                        double truth_sigma_m = 0,
                                        const Eigen::VectorXd& observed_with = {});

/// How the reported drift and its band did over runs whose true drift is known, per target: the
/// samples counted (those mean_normalised_squared_error counts), the RMS of estimate - truth [m],
/// the RMS of the sigma (times the factor) [m], and the share of them within ±2 sqrt((factor
/// sigma)^2 + truth_sigma_m^2) (factor empty: 1; truth_sigma_m the measured truth's white noise);
/// NaN where none counted. Same runs, truths and errors as mean_normalised_squared_error.
struct DriftBandScore {
  Eigen::VectorXi samples;
  Eigen::VectorXd rms_error_m, coverage, rms_sigma_m;
};
DriftBandScore drift_band_score(const std::vector<ObserverRun>& runs,
                                const std::vector<Eigen::MatrixXd>& truths,
                                const Eigen::VectorXd& factor = {}, double truth_sigma_m = 0);

/// The factor on the reported sigma that makes the share `coverage` of the runs' samples lie
/// within ±2 sigma of their true drift: per target the `coverage` quantile of |estimate - truth| /
/// (2 sigma) times `observed_with` (empty: 1); 1 where no sample counted. Unlike
/// drift_sigma_calibration it aims at the band's coverage itself, which errors with heavier
/// tails than a Gaussian's miss at a mean normalised squared error of 1. Same runs and truths,
/// same sizes and errors as mean_normalised_squared_error; throws SolverError for a coverage
/// outside (0, 1).
Eigen::VectorXd drift_sigma_coverage_calibration(const std::vector<ObserverRun>& runs,
                                                 const std::vector<Eigen::MatrixXd>& truths,
                                                 double coverage = 0.95,
                                                 const Eigen::VectorXd& observed_with = {});

}  // namespace tt::solvers
