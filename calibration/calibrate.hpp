// Closing the loop: the declared model against measured runs, the effect it misses, and the
// augmented model written as a case file, with RMS figures on test runs before and after.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calibration/effects.hpp"
#include "core/case_spec.hpp"
#include "core/error_figures.hpp"
#include "io/measured_data.hpp"
#include "mesh/tet_mesh.hpp"

namespace tt::calibration {

/// Post-processing of one sensor's simulated reading that the case file cannot express.
struct SensorCorrection {
  std::string sensor;
  double offset_K = 0;  /// added to the reading [K]
  double lag_s = 0;     /// first-order lag of the reading [s], 0 for none
};

/// The case with effects declared: `spec` (a valid case; read_case of its resolved TOML gives it
/// back) and the sensor corrections applied to its readings.
struct AugmentedCase {
  core::CaseSpec spec;
  std::vector<SensorCorrection> sensors;
  /// Index in `spec.groups` of each boundary group of the case it was made from (a heat input
  /// inserts groups); empty: the same indices.
  std::vector<int> group_at;
};

/// `spec` with one fitted effect declared (its indices those of the case `base` was made from).
/// Heat inputs become boundary groups (the patch's box intersected with each group it covers,
/// inserted just before that group so they take its faces) with the covered group's convection
/// and a surface flux; air temperature becomes sink tables; conductances, gains, coefficients and
/// material values are changed in place.
AugmentedCase augmented_case(const AugmentedCase& base, const Candidate& c,
                             const std::vector<double>& parameters, const Readout& r);

/// Readings corrected for sensor offsets and lags: #samples x #channels.
Eigen::MatrixXd corrected(const Eigen::MatrixXd& channels, const Eigen::VectorXd& times,
                          const Readout& r, const std::vector<SensorCorrection>& corrections);

struct RmsFigures {
  double temperature_rms_K = 0;
  double displacement_rms_m = 0;
};
/// RMS over the finite samples of measured - simulated (temperatures, displacements).
RmsFigures rms_figures(const std::vector<Eigen::MatrixXd>& measured,
                       const std::vector<Eigen::MatrixXd>& simulated, int sensors);

struct TestRun {
  std::string name;
  Eigen::VectorXd times;
  Eigen::MatrixXd measured, before, after;  /// #samples x #channels [K | m]
  AugmentedCase augmented;
};

/// A training run as the report names it.
struct TrainingRun {
  std::string name;
  bool air_from_sensor = false;  /// the run's air read from its ambient sensor, not fitted
};

/// What a report needs to name the places of a catalogue's candidates: the declared case (its
/// groups, bodies, sources and materials), the channels' ids and the training runs.
struct Naming {
  core::CaseSpec spec;
  std::vector<std::string> channel_ids;
  std::vector<TrainingRun> runs;
};
/// `cat`'s names: its first run's case, its readout's ids, its runs. (Inline, as `reported`: io
/// describes a catalogue's fits with them without linking the choice.)
inline Naming naming(const Catalogue& cat) {
  Naming n;
  if (!cat.runs.empty()) n.spec = cat.runs.front().spec;
  n.channel_ids = cat.readout.ids;
  for (const auto& run : cat.runs) n.runs.push_back({run.name, run.air.size() > 0});
  return n;
}

/// A claimed air's change on one test run: the sink of its first entry in the augmented case.
struct TestSink {
  std::string run;
  core::TimeTable sink;  /// as the case holds it: [s], [degC]
};

/// A fitted candidate as reported: the candidate (without its columns and unit loads) and its fit.
struct ReportedEffect {
  Candidate candidate;
  EffectFit fit;
  bool claimed = false;
  std::vector<TestSink> test_sinks;  /// a claimed per-run air: per test run
};
/// `fit` of `cat`'s candidate as reported.
inline ReportedEffect reported(const Catalogue& cat, const EffectFit& fit, bool claimed) {
  const Candidate& c = cat.candidates.at(static_cast<size_t>(fit.candidate));
  // The candidate without its responses: what it is, where it acts, its parameters' names.
  Candidate what{c.name, c.effect, c.parameters, c.per_run, c.fixed, {}, {}, {}, {}};
  return {std::move(what), fit, claimed, {}};
}

/// Selection::ambiguous with its candidates.
struct ReportedAmbiguity {
  ReportedEffect first, second;
  double difference = 0, spread = 0;  /// as in Ambiguity
  int channel = -1;                   /// index into the channels
  double channel_difference = 0;      /// [sigmas]
};
inline ReportedAmbiguity reported(const Catalogue& cat, const Ambiguity& a) {
  return {reported(cat, a.first, false),
          reported(cat, a.second, false),
          a.difference,
          a.spread,
          a.channel,
          a.channel_difference};
}

/// Selection::pairs with their candidates (the members' fits with the joint parameters).
struct ReportedPair {
  ReportedEffect first, second;
  double score = 0, heldout_gain = 0;
  std::vector<double> fold_gains;
  double adds_first = 0, adds_second = 0;
  bool admissible = false;
};

struct CalibrationResult {
  Selection selection;
  std::vector<TestRun> tests;
  RmsFigures before, after;
  std::vector<std::vector<double>> training_run_parameters;  /// per claimed effect, per-run fits
  Naming naming;                        /// of the catalogue the claims were chosen from
  std::vector<ReportedEffect> effects;  /// claimed, most important first
  std::vector<ReportedEffect> runners_up;
  /// Mechanisms the choice could not tell apart (Selection::ambiguous).
  std::vector<ReportedAmbiguity> ambiguous;
  /// Claims whose size refitted about the updated model is unphysical (Selection::refit_rejected):
  /// not claimed.
  std::vector<ReportedEffect> refit_rejected;
  std::vector<ReportedPair> pairs;
};

/// Selects effects on `train` (a catalogue built from the training runs) and evaluates the
/// declared and the augmented model on `test` runs as the written case file reads back (the
/// augmented case meshed again). On a reduced `model` the augmented case's operators are
/// projected on the same basis when its mesh has the same tets; otherwise, and in full order,
/// its full system is marched.
CalibrationResult calibrate(const MarchModel& model, const core::CaseSpec& declared,
                            const Catalogue& train, const std::vector<io::MeasuredRun>& test,
                            const CalibrationOptions& options);

/// One channel's test residual, measured - simulated, over the finite samples of all runs, in
/// the channel's unit [K | m].
using ChannelFigures = core::ErrorFigures;
ChannelFigures channel_figures(const std::vector<Eigen::MatrixXd>& measured,
                               const std::vector<Eigen::MatrixXd>& simulated, int channel);

}  // namespace tt::calibration
