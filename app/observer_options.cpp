#include "app/observer_options.hpp"

#include <algorithm>
#include <string_view>
#include <tuple>

#include "app/cli_numbers.hpp"
#include "core/errors.hpp"
#include "core/text.hpp"
#include "io/reports.hpp"
#include "io/sigma_calibration_io.hpp"

namespace tt::app {
namespace {

/// One value per name from an option: one value for all, or one each.
Eigen::VectorXd per_name(const std::vector<double>& values, const std::vector<std::string>& names,
                         const std::string& option, const std::string& what) {
  const auto n = static_cast<Eigen::Index>(names.size());
  if (values.size() == 1) return Eigen::VectorXd::Constant(n, values[0]);
  if (values.size() == names.size()) return Eigen::Map<const Eigen::VectorXd>(values.data(), n);
  throw core::DataError(option + ": " + std::to_string(values.size()) + " values for " +
                        std::to_string(names.size()) + " " + what + " (" +
                        core::joined(names, ",") + "); expected one value for all or one per " +
                        what + " in that order");
}

/// --expansion-relative-sigma per material of the set-up; none when every value is 0. DataError
/// when one is above 0 and the reduced model keeps no drift rows per material.
Eigen::VectorXd expansion_sigmas(const std::vector<double>& values,
                                 const solvers::ObserverSetup& setup) {
  if (std::all_of(values.begin(), values.end(), [](double v) { return v == 0; }))
    return Eigen::VectorXd();
  if (setup.expansion_materials.empty())
    throw core::DataError(
        "--expansion-relative-sigma: the reduced model keeps no drift rows per material (written "
        "before they were); rebuild it with `thermotwin reduce`");
  return per_name(values, setup.expansion_materials, "--expansion-relative-sigma", "materials");
}

/// Each material's expansion relative sigma by name ({} when none).
nlohmann::json expansion_json(const solvers::ObserverSetup& setup) {
  nlohmann::json j = nlohmann::json::object();
  const Eigen::VectorXd& e = setup.noise.expansion_relative_sigma;
  for (Eigen::Index m = 0; m < e.size(); ++m)
    j[setup.expansion_materials.at(static_cast<std::size_t>(m))] = e(m);
  return j;
}

/// A probe cycle's drift readings (observe, compensate --rom): how often, their noise, the factor
/// on the sigma of the filter that reads them.
void add_drift_reading_options(CLI::App& command, ObserverOptions& o) {
  command
      .add_option("--drift-readings-every-s", o.drift_readings_every_s,
                  "read the columns named after targets (dx, dy, dz, <axis point>_dy, ...; um) as "
                  "drift readings, one every this many seconds: a probe cycle measuring the tool "
                  "now and then, which sees what no temperature shows (a wrong expansion "
                  "coefficient); default 0: none")
      ->check(non_negative_number());
  command
      .add_option("--probed-drift-sigma-scale", o.probed_drift_sigma_scale,
                  "with --drift-readings-every-s: the factor on the reported drift sigma of the "
                  "filter that reads them, calibrated on runs observed with the probe cycle (the "
                  "readings narrow it); one value for all targets or one per target, "
                  "comma-separated (default: --drift-sigma-scale; the drift test keeps that)")
      ->delimiter(',')
      ->check(positive_number());
  command
      .add_option("--drift-reading-sigma-um", o.drift_reading_sigma_um,
                  "white noise of a drift reading [um] (default 0.3)")
      ->check(positive_number());
}

/// Gated terms act on the alarm and the evidence: refuses options whose settings of them differ
/// from the ones the file chose its pair with (`file` names it).
void check_same_consistency(const ObserverOptions& o, const solvers::ConsistencyOptions& chosen,
                            const std::string& file) {
  // The evidence's settings, when not given, are the file's (observer_setup takes them): only a
  // given one is checked.
  const std::tuple<const char*, const char*, double, double, bool> settings[] = {
      {"window_s", "--window-s", o.window_s, chosen.window_s, true},
      {"sustain_s", "--sustain-s", o.sustain_s, chosen.sustain_s, true},
      {"probability", "--probability", o.probability, chosen.probability, true},
      {"sensor_fault_sigmas", "--sensor-fault-sigmas", o.sensor_fault_sigmas,
       chosen.sensor_fault_sigmas, true},
      {"model_residual_sigmas", "--model-residual-sigmas", o.model_residual_sigmas,
       chosen.model_residual_sigmas, true},
      {"evidence_time_s", "--evidence-time-s", o.evidence_time_s, chosen.evidence_time_s,
       o.evidence_given},
      {"evidence_onset_sigmas", "--evidence-onset-sigmas", o.evidence_onset_sigmas,
       chosen.evidence_onset_sigmas, o.evidence_given}};
  for (const auto& [key, flag, given, in_file, checked] : settings) {
    if (checked && given != in_file)
      throw core::DataError("--sigma-calibration " + file + ": changed_machine.consistency." + key +
                            " = " + nlohmann::json(in_file).dump() +
                            ": its gated relative sigmas were chosen with that setting, not " +
                            flag + " " + nlohmann::json(given).dump() + "; give " + flag + " " +
                            nlohmann::json(in_file).dump() + ", or choose them again");
  }
}

/// The factors of --sigma-calibration's file on `setup`, and the relative sigmas it chose on
/// changed runs. DataError naming the file when it was calibrated for other sensors, targets or
/// probe cycle, or when --drift-sigma-scale or --probed-drift-sigma-scale is given too (or
/// --correction-relative-sigma or --expansion-relative-sigma, when it chose those, or a gate's
/// flag other than the file's gate, or alarm and evidence settings other than a gated pair's).
void apply_sigma_calibration(const ObserverOptions& o, const io::SigmaCalibrationFile& f,
                             const std::vector<std::string>& sensors,
                             solvers::ObserverSetup& setup) {
  const std::string file = o.sigma_calibration.string();
  if (!o.drift_sigma_scale.empty() || !o.probed_drift_sigma_scale.empty())
    throw core::DataError(
        "--sigma-calibration " + file +
        ": give it or --drift-sigma-scale / --probed-drift-sigma-scale, not both");
  if (f.sensors != sensors)
    throw core::DataError(file + ": sensors = " + core::joined(f.sensors, ",") +
                          ": calibrated for other " + "sensors than the ones read here (" +
                          core::joined(sensors, ",") + "); calibrate again with these (--sensors)");
  if (f.targets != setup.target_names)
    throw core::DataError(file + ": targets = " + core::joined(f.targets, ",") +
                          ": calibrated on another reduced model (its targets are " +
                          core::joined(setup.target_names, ",") + ")");
  if (o.drift_readings_every_s > 0 && f.probe_every_s &&
      *f.probe_every_s != o.drift_readings_every_s)
    throw core::DataError(file + ": probe_cycle.every_s = " + std::to_string(*f.probe_every_s) +
                          ": calibrated with another probe cycle than --drift-readings-every-s " +
                          std::to_string(o.drift_readings_every_s));
  setup.noise.drift_sigma_scale = f.drift_sigma_scale;
  if (f.probe_every_s) setup.noise.probed_drift_sigma_scale = f.probed_drift_sigma_scale;
  if (!f.correction_relative_sigma) return;
  if (gives_changed_terms(o))
    throw core::DataError("--sigma-calibration " + file +
                          ": its changed_machine chose the correction's and the expansion's "
                          "relative sigma; give it or --correction-relative-sigma / "
                          "--expansion-relative-sigma, not both");
  if (const auto gate = changed_terms_gate(o);
      gate != solvers::ChangedTermsGate::always && gate != f.changed_terms)
    throw core::DataError("--sigma-calibration " + file + ": changed_machine.gate = \"" +
                          io::changed_terms_gate_name(f.changed_terms) +
                          "\": its relative sigmas were chosen with the terms acting so; choose "
                          "them again with " +
                          io::changed_terms_gate_flag(gate) + ", or leave the flag out");
  if (f.changed_terms != solvers::ChangedTermsGate::always && f.consistency) {
    check_same_consistency(o, *f.consistency, file);
    setup.consistency.evidence_time_s = f.consistency->evidence_time_s;
    setup.consistency.evidence_onset_sigmas = f.consistency->evidence_onset_sigmas;
  }
  setup.noise.correction_relative_sigma = *f.correction_relative_sigma;
  setup.noise.changed_terms = f.changed_terms;
  setup.noise.expansion_relative_sigma =
      expansion_sigmas({f.expansion_relative_sigma.value_or(0.0)}, setup);
}

}  // namespace

void add_observer_options(CLI::App& command, ObserverOptions& o) {
  command
      .add_option("--sensors", o.sensors,
                  "sensor ids to read (default: every sensor of the run the model names)")
      ->delimiter(',');
  command
      .add_option("--sensor-sigma-k", o.sensor_sigma_k,
                  "white noise of a reading [K]: one value for all sensors or one per sensor, "
                  "comma-separated (default 0.05)")
      ->delimiter(',')
      ->check(positive_number());
  command
      .add_option("--heat-walk-w", o.heat_walk_w,
                  "random walk of each unknown heat input [W per sqrt(h)] (default 4)")
      ->check(non_negative_number());
  command
      .add_option("--heat-initial-w", o.heat_initial_w,
                  "each unknown heat input's spread at t = 0 [W] (default 2)")
      ->check(non_negative_number());
  command
      .add_option("--air-walk-k", o.air_walk_k,
                  "random walk of the air temperature offset [K per sqrt(h)] (default 0.5)")
      ->check(non_negative_number());
  command
      .add_option("--air-initial-k", o.air_initial_k,
                  "the air temperature offset's spread at t = 0 [K] (default 0.3)")
      ->check(non_negative_number());
  command
      .add_option("--state-walk-k", o.state_walk_k,
                  "white process noise on every reduced state [K per sqrt(h)]: model-form error "
                  "no unknown input explains (default 0)")
      ->check(non_negative_number());
  command
      .add_option("--sensor-offset-k", o.sensor_offset_k,
                  "an offset state per sensor, estimated beside the heat: its spread at t = 0 [K] "
                  "(default 0.5, a class B Pt100's tolerance at 40 degC; 0 with a walk of 0: "
                  "none, an offset is read as heat)")
      ->check(non_negative_number());
  command
      .add_option("--sensor-offset-walk-k", o.sensor_offset_walk_k,
                  "random walk of each sensor's offset state [K per sqrt(h)] (default 0.05: "
                  "0.1 K over a 4 h run, a contact or cable changing)")
      ->check(non_negative_number());
  command
      .add_option("--drift-relative-sigma", o.drift_relative_sigma,
                  "error of the drift rows (elastic model) relative to the drift (default 0.04)")
      ->check(non_negative_number());
  command
      .add_option("--correction-relative-sigma", o.correction_relative_sigma,
                  "error of the drift the filter's corrections account for (how far the unknown "
                  "inputs and readings moved it from the declared model's own run), relative to "
                  "it, added after --drift-sigma-scale (default 0: none)")
      ->check(non_negative_number());
  command
      .add_option("--expansion-relative-sigma", o.expansion_relative_sigma,
                  "error of each material's expansion coefficient relative to its declared "
                  "value, the materials independent: one value for all or one per material in "
                  "the case's order, comma-separated; adds each material's part of the drift "
                  "times it, after --drift-sigma-scale (default 0: none)")
      ->delimiter(',')
      ->check(non_negative_number());
  command
      .add_option("--drift-sigma-scale", o.drift_sigma_scale,
                  "factor on the reported drift sigma, calibrated on training runs: one value for "
                  "all targets or one per target, comma-separated (default 1)")
      ->delimiter(',')
      ->check(positive_number());
  command
      .add_option("--sigma-calibration", o.sigma_calibration,
                  "the factors on the reported drift sigma from a sigma_calibration.json that "
                  "`observe --train` wrote, for the same sensors and targets (in place of "
                  "--drift-sigma-scale and --probed-drift-sigma-scale)")
      ->check(CLI::ExistingFile);
  add_drift_reading_options(command, o);
  add_consistency_options(command, o);
}

void add_consistency_options(CLI::App& command, ObserverOptions& o) {
  command
      .add_option("--window-s", o.window_s,
                  "consistency test: window of the summed NIS [s] (default 1800)")
      ->check(positive_number());
  command
      .add_option("--sustain-s", o.sustain_s,
                  "consistency test: how long an exceedance lasts before recalibrate [s] "
                  "(default 900)")
      ->check(non_negative_number());
  command
      .add_option("--probability", o.probability,
                  "consistency test: chi-square quantile of the bound (default 0.999)")
      ->check(CLI::Range(0.5, 0.999999));
  command
      .add_option("--sensor-fault-sigmas", o.sensor_fault_sigmas,
                  "a sensor whose offset state stays beyond this many of its sigmas for "
                  "--sustain-s is reported faulty, by name (status sensor_fault; default 4, 0: "
                  "no such test)")
      ->check(non_negative_number());
  command
      .add_option("--model-residual-sigmas", o.model_residual_sigmas,
                  "a sensor whose reading stays more than this many of its sigmas from the "
                  "declared model's own run (no unknown input, no correction) for --sustain-s "
                  "says recalibrate (observer.json model_departures; default 3, 0: no such test)")
      ->check(non_negative_number());
  command
      .add_option("--evidence-time-s", o.evidence_time_s,
                  "--changed-terms-on-evidence weighs each sensor's residual against the "
                  "declared model's run averaged with this time constant, so that a reading's "
                  "noise does not widen the band [s] (default 300, 0: the residual itself; with "
                  "--sigma-calibration and neither this nor --evidence-onset-sigmas, its file's)")
      ->check(non_negative_number())
      ->each([&o](const std::string&) { o.evidence_given = true; });
  command
      .add_option("--evidence-onset-sigmas", o.evidence_onset_sigmas,
                  "--changed-terms-on-evidence's weight rises from 0 where a sensor's mean "
                  "residual leaves this many of its sigmas to 1 at --model-residual-sigmas "
                  "(default 1; with --sigma-calibration, as --evidence-time-s)")
      ->check(non_negative_number())
      ->each([&o](const std::string&) { o.evidence_given = true; });
  command.add_flag("--widen-on-inconsistency", o.widen_on_inconsistency,
                   "widen the reported drift sigma by sqrt(window NIS / window readings) while "
                   "that is above 1: the consistency window's innovations say by how much the "
                   "noise model is off (default: off)");
  CLI::Option* alarm =
      command.add_flag("--changed-terms-after-alarm", o.changed_terms_after_alarm,
                       "add --correction-relative-sigma's and --expansion-relative-sigma's terms "
                       "only once the filter says recalibrate: the band stays as calibrated until "
                       "the machine is seen to have changed (default: off, always)");
  command
      .add_flag("--changed-terms-on-evidence", o.changed_terms_on_evidence,
                "add those terms weighted by how far the readings have left the declared "
                "model's own run before the alarm: 0 while every sensor's mean residual is within "
                "--evidence-onset-sigmas of its sigmas, "
                "1 at --model-residual-sigmas; fully from the alarm on (default: off, always)")
      ->excludes(alarm);
}

solvers::ObserverSetup observer_setup(const ObserverOptions& o, const solvers::Twin& twin,
                                      const core::CaseSpec& spec,
                                      const std::vector<std::string>& sensors,
                                      const Eigen::MatrixXd& sensor_rows,
                                      const io::SigmaCalibrationFile* calibration) {
  solvers::ObserverNoise noise;
  noise.sensor_sigma_k = per_name(o.sensor_sigma_k, sensors, "--sensor-sigma-k", "sensors");
  noise.heat_walk_w = o.heat_walk_w;
  noise.heat_initial_w = o.heat_initial_w;
  noise.air_walk_k = o.air_walk_k;
  noise.air_initial_k = o.air_initial_k;
  noise.state_walk_k = o.state_walk_k;
  noise.sensor_offset_initial_k = o.sensor_offset_k;
  noise.sensor_offset_walk_k = o.sensor_offset_walk_k;
  noise.drift_relative_sigma = o.drift_relative_sigma;
  noise.drift_reading_sigma_m = 1e-6 * o.drift_reading_sigma_um;
  noise.correction_relative_sigma = o.correction_relative_sigma;
  noise.widen_on_inconsistency = o.widen_on_inconsistency;
  noise.changed_terms = changed_terms_gate(o);
  solvers::ObserverSetup setup =
      solvers::twin_observer_setup(twin, spec, sensors, noise, sensor_rows);
  setup.noise.expansion_relative_sigma = expansion_sigmas(o.expansion_relative_sigma, setup);
  if (!o.drift_sigma_scale.empty())
    setup.noise.drift_sigma_scale =
        per_name(o.drift_sigma_scale, setup.target_names, "--drift-sigma-scale", "targets");
  if (!o.probed_drift_sigma_scale.empty())
    setup.noise.probed_drift_sigma_scale = per_name(o.probed_drift_sigma_scale, setup.target_names,
                                                    "--probed-drift-sigma-scale", "targets");
  setup.consistency.window_s = o.window_s;
  setup.consistency.sustain_s = o.sustain_s;
  setup.consistency.probability = o.probability;
  setup.consistency.sensor_fault_sigmas = o.sensor_fault_sigmas;
  setup.consistency.model_residual_sigmas = o.model_residual_sigmas;
  setup.consistency.evidence_time_s = o.evidence_time_s;
  setup.consistency.evidence_onset_sigmas = o.evidence_onset_sigmas;
  if (!o.sigma_calibration.empty())
    apply_sigma_calibration(
        o, calibration ? *calibration : io::read_sigma_calibration(o.sigma_calibration), sensors,
        setup);
  return setup;
}

solvers::ChangedTermsGate changed_terms_gate(const ObserverOptions& o) {
  if (o.changed_terms_after_alarm) return solvers::ChangedTermsGate::after_alarm;
  if (o.changed_terms_on_evidence) return solvers::ChangedTermsGate::on_evidence;
  return solvers::ChangedTermsGate::always;
}

bool gives_changed_terms(const ObserverOptions& o) {
  return o.correction_relative_sigma > 0 ||
         std::any_of(o.expansion_relative_sigma.begin(), o.expansion_relative_sigma.end(),
                     [](double e) { return e > 0; });
}

nlohmann::json observer_noise_json(const solvers::ObserverSetup& setup) {
  const solvers::ObserverNoise& n = setup.noise;
  const Eigen::VectorXd scale = n.drift_sigma_scale.size() != 0
                                    ? n.drift_sigma_scale
                                    : Eigen::VectorXd::Ones(setup.target_rows.rows());
  nlohmann::json out = {
      {"sensor_sigma_K", io::as_vector(n.sensor_sigma_k)},
      {"heat_walk_W_per_sqrt_h", n.heat_walk_w},
      {"heat_initial_W", n.heat_initial_w},
      {"air_walk_K_per_sqrt_h", n.air_walk_k},
      {"air_initial_K", n.air_initial_k},
      {"state_walk_K_per_sqrt_h", n.state_walk_k},
      {"sensor_offset_K", n.sensor_offset_initial_k},
      {"sensor_offset_walk_K_per_sqrt_h", n.sensor_offset_walk_k},
      {"drift_relative_sigma", n.drift_relative_sigma},
      {"correction_relative_sigma", n.correction_relative_sigma},
      {"expansion_relative_sigma", expansion_json(setup)},
      {"drift_sigma_scale", io::as_vector(scale)},
      {"widen_on_inconsistency", n.widen_on_inconsistency},
      {"changed_terms", io::changed_terms_gate_name(n.changed_terms)},
      {"changed_terms_after_alarm", n.changed_terms == solvers::ChangedTermsGate::after_alarm}};
  if (n.probed_drift_sigma_scale.size() != 0)
    out["probed_drift_sigma_scale"] = io::as_vector(n.probed_drift_sigma_scale);
  return out;
}

}  // namespace tt::app
