// thermotwin observe CASE --rom DIR --data RUN --out DIR: the physics observer (docs/observer.md)
// on a measured run: a Kalman filter on the reduced model's states, fed with the run's spindle
// speed (its speed_rpm column) as the duty cycle and its sensors' readings, that predicts the
// drift at the tool (and the axis points) with its standard deviation and says when the
// innovations stop fitting the noise model (status `recalibrate`, with the time it started).
//   1. the case, the run and the training runs, the output claimed;
//   2. the reduced model, checked against the case and its mesh;
//   3. with --train, the factors on the reported sigma calibrated on runs whose drift was measured
//      (studies/observer_sigma.hpp; sigma_calibration.json), and with --changed the correction's
//      and the expansion's relative sigma chosen on runs of a changed machine; the study
//      (studies/observe_run.hpp): the case under the run's inputs, the sensors (--sensors, default:
//      every sensor of the run that is a named point of the model), the observer's set-up
//      (app/observer_options.hpp, with the calibrated factors), the run through the filter;
//   4. observer.csv and observer.json (io/observe_out.hpp), all or nothing.
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/observer_options.hpp"
#include "core/errors.hpp"
#include "core/units.hpp"
#include "io/atomic_dir.hpp"
#include "io/case_reader.hpp"
#include "io/measured_data.hpp"
#include "io/observe_out.hpp"
#include "io/reduced_model_io.hpp"
#include "io/reports.hpp"
#include "io/sigma_calibration_io.hpp"
#include "mesh/mesher.hpp"
#include "studies/observe_run.hpp"
#include "studies/observer_sigma.hpp"

namespace tt::app {

namespace {

/// The summary of a sigma calibration on stderr: the factors and the band's coverage before and
/// after, per measured target.
void print_calibration(const studies::SigmaCalibration& cal) {
  const auto pass = [&](const std::string& name, const studies::SigmaPass& p) {
    for (std::size_t t = 0; t < cal.targets.size(); ++t) {
      const auto k = static_cast<Eigen::Index>(t);
      if (p.pooled_before.samples(k) == 0) continue;
      std::cerr << "thermotwin: observe: " << name << " " << cal.targets[t] << ": factor "
                << p.drift_sigma_scale(k) << ", ±2 sigma held " << 100 * p.pooled_before.coverage(k)
                << " % of " << p.pooled_before.samples(k) << " training samples, now "
                << 100 * p.pooled_after.coverage(k) << " %\n";
    }
  };
  pass("sigma", cal.temperatures);
  if (cal.probed) pass("probed sigma", *cal.probed);
  if (!cal.changed) return;
  const studies::ChangedMachineSigma& ch = *cal.changed;
  const studies::SigmaTermsCandidate& pick = ch.pick();
  std::cerr << "thermotwin: observe: on the changed runs, correction relative sigma "
            << pick.correction_relative_sigma << " and expansion relative sigma "
            << pick.expansion_relative_sigma << "\n";
  for (std::size_t r = 0; ch.gate == solvers::ChangedTermsGate::after_alarm && r < ch.runs.size();
       ++r)
    if ((ch.before[r].samples.array() == 0).all())
      std::cerr << "thermotwin: observe:   changed run " << ch.runs[r]
                << " raised no alarm: with --changed-terms-after-alarm its band is never widened, "
                   "and it is not scored\n";
  for (std::size_t t = 0; t < cal.targets.size(); ++t) {
    const auto k = static_cast<Eigen::Index>(t);
    if (ch.grid.front().score.samples(k) == 0) continue;
    std::cerr << "thermotwin: observe:   " << cal.targets[t] << ": ±2 sigma held "
              << 100 * ch.grid.front().score.coverage(k) << " % of the changed runs' samples, now "
              << 100 * pick.score.coverage(k) << " %"
              << (ch.out_of_reach[t]
                      ? " (out of the terms' reach: the widest pair holds " +
                            std::to_string(100 * ch.grid.back().score.coverage(k)) + " %)"
                      : "")
              << "\n";
  }
  // Each gate's price on the training runs (RMS sigma / RMS error) beside its gain on the
  // changed runs (their coverage).
  for (const studies::GateChoice& g : ch.gates) {
    std::ostringstream held, width;
    held << std::fixed << std::setprecision(1);
    width << std::fixed << std::setprecision(2);
    for (std::size_t t = 0; t < cal.targets.size(); ++t) {
      const auto k = static_cast<Eigen::Index>(t);
      if (g.pick.score.samples(k) > 0)
        held << " " << cal.targets[t] << " " << 100 * g.pick.score.coverage(k) << " %";
      if (g.training.samples(k) > 0)
        width << " " << cal.targets[t] << " "
              << g.training.rms_sigma_m(k) / g.training.rms_error_m(k);
    }
    std::cerr << "thermotwin: observe:   gate " << io::changed_terms_gate_name(g.gate)
              << (g.gate == ch.gate ? " (chosen)" : "") << ": c "
              << g.pick.correction_relative_sigma << ", e " << g.pick.expansion_relative_sigma
              << "; ±2 sigma held on the changed runs"
              << (g.gate == solvers::ChangedTermsGate::after_alarm ? " from their alarm on" : "")
              << held.str() << "; RMS sigma / RMS error on the training runs" << width.str()
              << "\n";
  }
  if (!ch.evidence_settings.empty()) {
    const studies::EvidenceChoice& e = ch.evidence_settings.at(ch.evidence_chosen);
    const bool taken = ch.gate == solvers::ChangedTermsGate::on_evidence &&
                       ch.evidence.time_s == e.settings.time_s &&
                       ch.evidence.onset_sigmas == e.settings.onset_sigmas;
    std::cerr << "thermotwin: observe:   on evidence, the setting these runs choose of "
              << ch.evidence_settings.size() << " (changed_machine.evidence_settings): "
              << "--evidence-time-s " << e.settings.time_s << " --evidence-onset-sigmas "
              << e.settings.onset_sigmas << ", c " << e.choice.pick.correction_relative_sigma
              << ", e " << e.choice.pick.expansion_relative_sigma
              << "; RMS sigma / RMS error on the training runs, summed over the targets, "
              << e.choice.training_width
              << (taken ? " (taken)"
                  : ch.gate == solvers::ChangedTermsGate::on_evidence
                      ? " (not taken: --choose-evidence takes it)"
                      : "")
              << "\n";
  }
}

/// The sigma calibrated on the training runs (sigma_calibration.json into `dir`), `input` holding
/// the case, the reduced model, its mesh and the set-up; `options` then carry its factors and
/// sensors, for the run observed after it.
void calibrate_sigma(const ObserveArgs& args, const std::vector<io::MeasuredRun>& runs,
                     const std::vector<io::MeasuredRun>& changed,
                     studies::SigmaCalibrationInput input, ObserverOptions& options,
                     const std::filesystem::path& dir) {
  for (const auto& r : runs) input.runs.push_back(&r);
  for (const auto& r : changed) input.changed.push_back(&r);
  input.sensors = options.sensors;
  input.drift_readings_every_s = options.drift_readings_every_s;
  input.truth_sigma_m = core::kMetresPerMicrometre * args.truth_sigma_um;
  input.coverage = args.coverage;
  input.evidence_from_data = args.choose_evidence;
  if (!args.quiet)
    input.progress = [](const std::string& line) {
      std::cerr << "thermotwin: observe: " << line << "\n";
    };
  const studies::SigmaCalibration cal = studies::calibrate_observer_sigma(input);
  io::write_json(dir / "sigma_calibration.json",
                 io::sigma_calibration_json(cal, {input.declared->name, input.twin->model.states(),
                                                  args.rom, observer_noise_json(cal.setup)}));
  options.sensors = cal.sensors;
  options.sigma_calibration.clear();
  options.drift_sigma_scale = io::as_vector(cal.temperatures.drift_sigma_scale);
  options.probed_drift_sigma_scale.clear();
  if (cal.probed) options.probed_drift_sigma_scale = io::as_vector(cal.probed->drift_sigma_scale);
  if (cal.changed) {
    const studies::SigmaTermsCandidate& pick = cal.changed->pick();
    options.correction_relative_sigma = pick.correction_relative_sigma;
    options.expansion_relative_sigma = {pick.expansion_relative_sigma};
    options.evidence_time_s = cal.changed->evidence.time_s;
    options.evidence_onset_sigmas = cal.changed->evidence.onset_sigmas;
  }
  if (!args.quiet) print_calibration(cal);
}

/// The run's summary on stderr; a faulty sensor is a warning, written even with --quiet.
void print_observed(const studies::ObserveReport& report, bool quiet) {
  const solvers::ObserverRun& r = report.result;
  for (const solvers::HeldSensor& f : r.sensor_faults)
    std::cerr << "thermotwin: observe: warning: sensor "
              << report.sensors[static_cast<std::size_t>(f.sensor)]
              << " reads off by an offset (observer.json sensor_faults) since t = " << f.since_s
              << " s: check its mounting and calibration\n";
  if (quiet) return;
  std::cerr << "thermotwin: observe: " << r.times.size() << " samples, status "
            << (r.recalibrate
                    ? "recalibrate since t = " + std::to_string(r.recalibrate_since_s) + " s"
                    : std::string(r.sensor_faults.empty() ? "ok" : "sensor_fault"))
            << "\n";
  for (const solvers::HeldSensor& d : r.model_departures)
    std::cerr << "thermotwin: observe: sensor "
              << report.sensors[static_cast<std::size_t>(d.sensor)]
              << " read away from the declared model's run since t = " << d.since_s
              << " s, beginning near t = " << d.onset_s << " s (observer.json model_departures)\n";
  for (const solvers::HeldSensor& d : r.drift_departures)
    std::cerr << "thermotwin: observe: the drift readings of "
              << report.setup.target_names[static_cast<std::size_t>(d.sensor)]
              << " departed from the model since t = " << d.since_s
              << " s (observer.json drift_readings)\n";
}

}  // namespace

int observe_command(const ObserveArgs& args) {
  // 1. The case, the run and the training runs, the output claimed.
  const core::CaseSpec declared = io::read_case(args.case_file);
  std::optional<io::MeasuredRun> run;
  if (!args.data.empty()) run = io::read_measured_run(args.data);
  io::require_distinct_runs(args.train, "--train");
  io::require_distinct_runs(args.changed, "--changed");
  io::require_disjoint_runs(
      args.changed, args.train, "--changed", "--train",
      "a run is either of the machine the model declares or of a changed one");
  if (!args.changed.empty() && gives_changed_terms(args.observer))
    throw core::DataError(
        "observe: --changed chooses --correction-relative-sigma and --expansion-relative-sigma; "
        "give it or them, not both");
  if (args.choose_evidence && !args.observer.changed_terms_on_evidence)
    throw core::DataError(
        "observe: --choose-evidence chooses the evidence of --changed-terms-on-evidence; give "
        "that too");
  if (args.choose_evidence && args.observer.model_residual_sigmas <= 0)
    throw core::DataError(
        "observe: --choose-evidence chooses how the evidence is taken of the departure test, and "
        "--model-residual-sigmas 0 turns that test off");
  if (args.choose_evidence && args.observer.evidence_given)
    throw core::DataError(
        "observe: --choose-evidence chooses --evidence-time-s and --evidence-onset-sigmas; give "
        "it or them, not both");
  std::vector<io::MeasuredRun> training, changed;
  for (const auto& path : args.train) training.push_back(io::read_measured_run(path));
  for (const auto& path : args.changed) changed.push_back(io::read_measured_run(path));
  std::vector<std::filesystem::path> inputs = io::case_input_files(declared);
  inputs.push_back(args.rom);
  if (run) inputs.push_back(args.data);
  inputs.insert(inputs.end(), args.train.begin(), args.train.end());
  inputs.insert(inputs.end(), args.changed.begin(), args.changed.end());
  if (!args.observer.sigma_calibration.empty()) inputs.push_back(args.observer.sigma_calibration);
  io::OutputDir out(args.out, inputs);
  // 2. The reduced model, built for this machine and mesh.
  const io::ReducedModelFile rom = io::read_reduced_model(args.rom);
  const mesh::TetMesh mesh = mesh::mesh_case(declared);
  io::check_reduced_model_fits(rom, io::reduced_model_key(declared, mesh), args.rom);
  // 3. The sigma calibrated on the training runs, then the run observed with it: the set-up reads
  //    `options`, which the calibration sets to its factors and sensors once it is done.
  ObserverOptions options = args.observer;
  const auto setup = [&](const core::CaseSpec& spec, const std::vector<std::string>& sensors,
                         const Eigen::MatrixXd& rows) {
    return observer_setup(options, rom.twin, spec, sensors, rows);
  };
  if (!training.empty()) {
    studies::SigmaCalibrationInput input;
    input.declared = &declared;
    input.twin = &rom.twin;
    input.mesh = &mesh;
    input.setup = setup;
    calibrate_sigma(args, training, changed, input, options, out.path());
  }
  std::optional<studies::ObserveReport> report;
  if (run)
    report = studies::observe_run({&declared, &*run, &rom.twin, options.sensors, setup, &mesh,
                                   options.drift_readings_every_s});
  // 4. Outputs.
  if (report)
    io::write_observe(out.path(), *report,
                      {run->run, declared.name, rom.twin.model.states(), args.rom,
                       observer_noise_json(report->setup)});
  out.commit();
  if (report) print_observed(*report, args.quiet);
  return 0;
}

}  // namespace tt::app
