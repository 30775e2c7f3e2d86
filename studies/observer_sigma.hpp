// The physics observer's reported sigma calibrated on a user's training runs (docs/observer.md,
// "Calibrating the sigma"): runs whose tool drift was measured throughout (displacement columns
// named after the observer's targets) are observed as `observe` observes a run, and the factor on
// each target's sigma is chosen that puts the share `coverage` of their samples within ±2 sigma of
// the measured drift (solvers::drift_sigma_coverage_calibration). When the measured drift's own
// white noise is declared, the same rule reads the measured drift's mean over a few minutes
// (window_mean), which divides that noise and keeps the errors, slow as the machine's heat:
// subtracting the noise sample by sample under the quantile made the band too narrow on held-out
// runs, and the NEES rule with the noise taken out under-covered where the errors are near the
// noise (docs/observer.md). With a probe cycle the runs are also observed reading their drift
// every so often, and that filter gets its own factor, scored on the samples between readings. SI
// units.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "io/measured_data.hpp"
#include "studies/observe_run.hpp"
#include "studies/progress.hpp"

namespace tt::studies {

struct SigmaCalibrationInput {
  /// the declared case, the twin (checked against it), its mesh, the set-up: as ObserveInput's
  const core::CaseSpec* declared = nullptr;
  const solvers::Twin* twin = nullptr;
  const mesh::TetMesh* mesh = nullptr;
  ObserverSetupFor setup;
  std::vector<const io::MeasuredRun*> runs;  /// the training runs, at least one
  /// the sensors read; empty: the first run's readable sensors (observe_run's default), which
  /// every other run must have
  std::vector<std::string> sensors;
  /// > 0: also calibrate the filter that reads a probe cycle of this period [s]
  double drift_readings_every_s = 0;
  /// white noise of the measured drift [m] (0: counted as error): declared, the coverage rule
  /// reads the measured drift's mean over kDriftMeanWindowS
  /// (SigmaPass::averaged_drift_sigma_scale); the scores' band for the measured drift is ±2
  /// sqrt((factor sigma)^2 + truth_sigma_m^2)
  double truth_sigma_m = 0;
  double coverage = 0.95;  /// the share of samples the ±2 sigma band is to hold
  /// runs of a machine that has changed (an effect the declared model lacks), their drift measured
  /// as the training runs' is: with one or more, the correction's and the materials' expansion
  /// relative sigma are chosen on them (ChangedMachineSigma)
  std::vector<const io::MeasuredRun*> changed;
  /// with the terms on evidence: the pair chosen under the evidence setting the changed runs
  /// choose (ChangedMachineSigma::evidence_chosen) instead of the set-up's own
  bool evidence_from_data = false;
  Progress progress;  /// a line per run observed; may be empty
};

/// The window of the measured drift's mean that the averaged coverage rule reads [s]
/// (SigmaPass::averaged_drift_sigma_scale).
inline constexpr double kDriftMeanWindowS = 300;

/// Per column of `values` (#samples x #columns, rows at `times` [s], increasing) the mean of its
/// finite values within window_s / 2 of each sample, on either side; NaN where the sample itself
/// is NaN (a sample that was not measured stays so) or none is finite.
Eigen::MatrixXd window_mean(const Eigen::MatrixXd& values, const Eigen::VectorXd& times,
                            double window_s);

/// Which rule gave a target's factor: the coverage rule on the measured drift, or on its mean
/// over kDriftMeanWindowS (with the measured drift's noise declared).
enum class SigmaRule { coverage, averaged };

/// One filter's calibration (temperatures only, or with the probe cycle).
struct SigmaPass {
  /// per target: the factor on the reported sigma (the coverage rule's; with truth_sigma_m the
  /// averaged one's), the coverage rule's (the quantile, the noise counted as error), the NEES
  /// rule's (mean normalised squared error 1, the noise taken out; 1 where the errors are within
  /// it; recorded), the scale the runs were observed with; 1 where no sample had a measured drift
  Eigen::VectorXd drift_sigma_scale, coverage_drift_sigma_scale, nees_drift_sigma_scale,
      observed_with;
  /// with the measured drift's noise declared (truth_sigma_m > 0): the coverage rule on the
  /// measured drift averaged over kDriftMeanWindowS (window_mean), whose white noise the mean
  /// divides while the errors, which change over tens of minutes, stay; empty without
  Eigen::VectorXd averaged_drift_sigma_scale;
  std::vector<SigmaRule> rules;  /// per target: the rule of drift_sigma_scale
  /// per run, then pooled over the runs: RMS error and the band's coverage of the measured drift
  /// before (the sigma observed with) and after (times drift_sigma_scale / observed_with), the
  /// band widened by truth_sigma_m
  std::vector<solvers::DriftBandScore> before, after;
  solvers::DriftBandScore pooled_before, pooled_after;
};

/// One pair of the correction's relative sigma c
/// (solvers::ObserverNoise::correction_relative_sigma) and an expansion relative sigma e for every
/// material (expansion_relative_sigma), scored on the changed runs.
struct SigmaTermsCandidate {
  double correction_relative_sigma = 0, expansion_relative_sigma = 0;
  solvers::DriftBandScore score;  /// pooled over the changed runs
  double width = 0;               /// over the measured targets: the sum of RMS sigma / RMS error
  bool reaches_goal = false;      /// every measured target's goal reached (ChangedMachineSigma)
};

/// One gate's choice beside the others' (ChangedMachineSigma::gates): the pair the rule takes with
/// the terms acting so, and what that pair costs on the training runs, a machine that has not
/// changed (its band with the factors and the pair, scored as the factors were).
struct GateChoice {
  solvers::ChangedTermsGate gate = solvers::ChangedTermsGate::always;
  SigmaTermsCandidate pick;          /// scored on the changed runs, as the gate scores them
  solvers::DriftBandScore training;  /// pooled over the training runs
  double training_width = 0;         /// over the measured targets: sum of RMS sigma / RMS error
};

/// One setting of the evidence (solvers::EvidenceSettings) with the pair the rule takes under it
/// for terms on evidence, and that pair's price on the training runs
/// (ChangedMachineSigma::evidence_settings).
struct EvidenceChoice {
  solvers::EvidenceSettings settings;
  GateChoice choice;  /// its gate on_evidence
  bool reaches_goal =
      false;  /// every measured target's goal (ChangedMachineSigma::evidence_chosen)
};

/// The evidence settings tried (ChangedMachineSigma::evidence_settings): time constants [s] and
/// onsets [sigmas]; the bound stays the departure test's.
inline constexpr double kEvidenceTimes[] = {0, 60, 300, 900, 1800};
inline constexpr double kEvidenceOnsets[] = {0, 0.5, 1, 1.5, 2};

/// How far below the widest pair's coverage an out-of-reach target's goal is (ChangedMachineSigma).
inline constexpr double kReachTolerance = 0.01;

/// c and e chosen on runs of a changed machine (docs/observer.md, "A machine that has changed"):
/// the sigma calibrated where the model holds (the factors) with (c d_c)^2 and the sum over the
/// materials of (e d_m)^2 added (solvers::DriftSigmaTerms). The sigma grows with c and e sample by
/// sample, so the grid's widest pair covers the most in every target. A measured target where even
/// that pair covers less than `coverage` is out of the terms' reach (a drift no term follows: a
/// heat input off the unknown inputs' shapes moves dx on SB-1; gated terms that act late or
/// weakly): its goal is the widest pair's coverage less kReachTolerance, since asking for the
/// last few samples the terms reach would take the widest pair every time, and leaving the target
/// out would leave a rule with no target at c = e = 0. Rule: the narrowest pair (least width)
/// that reaches every measured target's goal (`coverage`, or that). The grid: c over
/// 0, 0.25, 0.5, 1, 2, 4 and e over 0, 0.05, 0.1, 0.15, 0.2, 0.3 (e 0 only when the reduced model
/// keeps no drift rows per material).
struct ChangedMachineSigma {
  std::vector<std::string> runs;  /// the changed runs' names
  /// when the terms act (the set-up's ObserverNoise::changed_terms); after the alarm, the changed
  /// runs are scored on their samples from the alarm on, where the terms act (a run that raises
  /// nothing counts no sample); always and on evidence, on every sample
  solvers::ChangedTermsGate gate = solvers::ChangedTermsGate::always;
  std::vector<SigmaTermsCandidate> grid;
  /// per target: measured by a changed run and covered less than `coverage` even by the widest
  /// pair (left out of the rule)
  std::vector<bool> out_of_reach;
  std::size_t chosen = 0;  /// the chosen pair's index in grid
  const SigmaTermsCandidate& pick() const { return grid.at(chosen); }
  /// per changed run: the score at c = e = 0 and at the chosen pair
  std::vector<solvers::DriftBandScore> before, after;
  /// every gate's choice (always, on evidence, after the alarm; `gate`'s is this one's), from the
  /// same observation of the changed runs: what a tight band on a healthy machine costs in
  /// coverage of a changed one
  std::vector<GateChoice> gates;
  /// Terms on evidence with every evidence setting (kEvidenceTimes x kEvidenceOnsets, the bound
  /// the set-up's model_residual_sigmas), from the same observation, each with its pair (the rule
  /// above) and that pair's price on the training runs; empty without the departure test
  /// (model_residual_sigmas 0), which the evidence is taken of.
  std::vector<EvidenceChoice> evidence_settings;
  /// The setting on evidence that the data choose: per measured target a goal of `coverage`, or
  /// kReachTolerance below the best coverage any setting's pair gives; of the settings whose pair
  /// reaches every goal, the one with the narrowest band on the training runs (training_width);
  /// when none does (targets best covered under different settings), the one that falls least
  /// short of a goal.
  std::size_t evidence_chosen = 0;
  /// the evidence setting `grid` was scored under (the set-up's own, or with evidence_from_data
  /// and the terms on evidence the one chosen); what the alarm and evidence settings the pair
  /// was chosen with (sigma_calibration.json changed_machine.consistency) say of the evidence
  solvers::EvidenceSettings evidence;
};

struct SigmaCalibration {
  std::vector<std::string> runs;              /// the training runs' names
  std::vector<std::string> sensors;           /// read, in order
  std::vector<std::string> targets;           /// the observer's, in order
  std::vector<std::string> measured_targets;  /// those some run measured
  solvers::ObserverSetup setup;               /// the first run's (its noise model, for a report)
  double coverage = 0.95, truth_sigma_m = 0;
  SigmaPass temperatures;
  double drift_readings_every_s = 0;
  std::optional<SigmaPass> probed;  /// with a probe cycle
  /// with changed runs: c and e chosen on them, for the filter that reads temperatures only
  std::optional<ChangedMachineSigma> changed;
};

/// `run` with the sigma that its terms (solvers::DriftSigmaTerms) make with `factor` on the sigma
/// it was observed with (per target; empty: 1), the correction's relative sigma c and an expansion
/// relative sigma e for every material, as `gate` lets them act: as the observer would have
/// reported it with them.
solvers::ObserverRun with_sigma(const solvers::ObserverRun& run, const Eigen::VectorXd& factor,
                                double c, double e,
                                solvers::ChangedTermsGate gate = solvers::ChangedTermsGate::always);

/// `run` with each sample's evidence (solvers::DriftSigmaTerms::evidence) taken under `settings`
/// (solvers::evidence_of): as the observer would have reported it with them. Its sigma is left as
/// it was (with_sigma makes it).
solvers::ObserverRun with_evidence(solvers::ObserverRun run,
                                   const solvers::EvidenceSettings& settings);

/// `truth` (#samples x #targets) with NaN at every sample where `read` (drift readings of the same
/// samples, NaN where none) holds a reading: a probe-cycle filter is scored between its readings,
/// since at a reading it is pulled to the very value it would be scored on.
Eigen::MatrixXd between_readings(const Eigen::MatrixXd& truth, const Eigen::MatrixXd& read);

/// Throws DataError naming the run when a training or changed run has no displacement column
/// named after a target, or lacks a sensor the first run gives; what observe_run throws.
SigmaCalibration calibrate_observer_sigma(const SigmaCalibrationInput& input);

}  // namespace tt::studies
