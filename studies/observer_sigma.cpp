#include "studies/observer_sigma.hpp"

#include <algorithm>
#include <limits>

#include "core/errors.hpp"

namespace tt::studies {
namespace {

/// The training runs observed by one filter, and their measured drift.
struct Observed {
  std::vector<solvers::ObserverRun> runs;
  std::vector<Eigen::MatrixXd> truths;
  Eigen::VectorXd observed_with;
};

/// The scale a filter reports its sigma with: `scale`, or 1 per target when unset.
Eigen::VectorXd scale_or_ones(const Eigen::VectorXd& scale, Eigen::Index targets) {
  return scale.size() != 0 ? scale : Eigen::VectorXd::Ones(targets);
}

SigmaPass calibrate_pass(const Observed& o, const SigmaCalibrationInput& input) {
  SigmaPass pass;
  pass.observed_with = o.observed_with;
  pass.coverage_drift_sigma_scale =
      solvers::drift_sigma_coverage_calibration(o.runs, o.truths, input.coverage, o.observed_with);
  pass.nees_drift_sigma_scale =
      solvers::drift_sigma_calibration(o.runs, o.truths, input.truth_sigma_m, o.observed_with);
  pass.drift_sigma_scale = pass.coverage_drift_sigma_scale;
  pass.rules.assign(static_cast<std::size_t>(pass.drift_sigma_scale.size()), SigmaRule::coverage);
  if (input.truth_sigma_m > 0) {
    // The NEES rule with the noise taken out, where the errors are above the noise; where they
    // are not, the measured drift cannot place the band under its noise, and the coverage rule
    // (the noise counted as error) errs wide.
    const Eigen::VectorXd nees =
        solvers::mean_normalised_squared_error(o.runs, o.truths, input.truth_sigma_m);
    for (Eigen::Index t = 0; t < nees.size(); ++t)
      if (nees(t) > 0) {
        pass.drift_sigma_scale(t) = pass.nees_drift_sigma_scale(t);
        pass.rules[static_cast<std::size_t>(t)] = SigmaRule::nees;
      }
  }
  const Eigen::VectorXd factor = pass.drift_sigma_scale.cwiseQuotient(o.observed_with);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(factor.size());
  const double noise = input.truth_sigma_m;
  for (std::size_t k = 0; k < o.runs.size(); ++k) {
    pass.before.push_back(solvers::drift_band_score({o.runs[k]}, {o.truths[k]}, ones, noise));
    pass.after.push_back(solvers::drift_band_score({o.runs[k]}, {o.truths[k]}, factor, noise));
  }
  pass.pooled_before = solvers::drift_band_score(o.runs, o.truths, ones, noise);
  pass.pooled_after = solvers::drift_band_score(o.runs, o.truths, factor, noise);
  return pass;
}

}  // namespace

Eigen::MatrixXd between_readings(const Eigen::MatrixXd& truth, const Eigen::MatrixXd& read) {
  Eigen::MatrixXd between = truth;
  for (Eigen::Index i = 0; i < between.rows(); ++i)
    if (read.row(i).array().isFinite().any())
      between.row(i).setConstant(std::numeric_limits<double>::quiet_NaN());
  return between;
}

SigmaCalibration calibrate_observer_sigma(const SigmaCalibrationInput& input) {
  if (input.runs.empty())
    throw core::DataError("sigma calibration: no training run (give at least one)");
  SigmaCalibration cal;
  cal.coverage = input.coverage;
  cal.truth_sigma_m = input.truth_sigma_m;
  cal.drift_readings_every_s = input.drift_readings_every_s;
  cal.sensors = input.sensors;
  Observed blind, probed;
  std::vector<bool> measured;
  for (const io::MeasuredRun* run : input.runs) {
    ObserveInput in{input.declared, run, input.twin, cal.sensors, input.setup, input.mesh, 0.0};
    const ObserveReport report = observe_run(in);
    if (cal.sensors.empty()) cal.sensors = report.sensors;
    const std::vector<std::string>& targets = report.setup.target_names;
    const auto nt = static_cast<Eigen::Index>(targets.size());
    if (cal.targets.empty()) {
      cal.setup = report.setup;
      cal.targets = targets;
      measured.assign(targets.size(), false);
      blind.observed_with = scale_or_ones(report.setup.noise.drift_sigma_scale, nt);
      probed.observed_with = scale_or_ones(report.setup.noise.probed_drift_sigma_scale.size() != 0
                                               ? report.setup.noise.probed_drift_sigma_scale
                                               : report.setup.noise.drift_sigma_scale,
                                           nt);
    }
    const DriftReadings truth =
        drift_columns(*run, targets, "a training run of the sigma calibration");
    for (std::size_t t = 0; t < targets.size(); ++t)
      measured[t] = measured[t] || std::find(truth.targets.begin(), truth.targets.end(),
                                             targets[t]) != truth.targets.end();
    cal.runs.push_back(run->run);
    blind.runs.push_back(report.result);
    blind.truths.push_back(truth.readings);
    if (input.progress)
      input.progress("sigma calibration: " + run->run + " observed (" +
                     std::to_string(cal.runs.size()) + " of " + std::to_string(input.runs.size()) +
                     " runs" +
                     (input.drift_readings_every_s > 0 ? ", with the probe cycle next" : "") + ")");
    if (input.drift_readings_every_s <= 0) continue;
    in.drift_readings_every_s = input.drift_readings_every_s;
    probed.runs.push_back(observe_run(in).result);
    probed.truths.push_back(between_readings(
        truth.readings, drift_readings(*run, targets, input.drift_readings_every_s).readings));
  }
  for (std::size_t t = 0; t < cal.targets.size(); ++t)
    if (measured[t]) cal.measured_targets.push_back(cal.targets[t]);
  cal.temperatures = calibrate_pass(blind, input);
  if (input.drift_readings_every_s > 0) cal.probed = calibrate_pass(probed, input);
  return cal;
}

}  // namespace tt::studies
