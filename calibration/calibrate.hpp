// Closing the loop: the declared model against measured runs, the effect it misses, and the
// augmented model written as a case file, with RMS figures on test runs before and after.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
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
};

/// `spec` with one fitted effect declared. Heat inputs become boundary groups (the patch's box
/// intersected with each group it covers, inserted just before that group so they take its
/// faces) with the covered group's convection and a surface flux; air temperature becomes sink
/// tables; conductances, gains, coefficients and material values are changed in place.
AugmentedCase augmented_case(const AugmentedCase& base, const Candidate& c,
                             const std::vector<double>& parameters, const Readout& r);

/// Readings corrected for sensor offsets and lags: #samples x #channels.
Eigen::MatrixXd corrected(const Eigen::MatrixXd& channels, const Eigen::VectorXd& times,
                          const Readout& r, const std::vector<SensorCorrection>& corrections);

struct RmsFigures {
  double temperature_rms_K = 0;
  double displacement_rms_um = 0;
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

struct CalibrationResult {
  Selection selection;
  std::vector<TestRun> tests;
  RmsFigures before, after;
  std::vector<std::vector<double>> training_run_parameters;  /// per claimed effect, per-run fits
  nlohmann::json effects;  /// claimed: {kind, parameters, location, explained_fraction, ...}
  nlohmann::json runners_up;
  /// Mechanisms the choice could not tell apart (Selection::ambiguous): each {candidates: [two
  /// descriptions as in `effects`], score_difference, spread, distinguishing_channel, hint}.
  nlohmann::json ambiguous;
  /// Claims whose size refitted about the updated model is unphysical (Selection::refit_rejected),
  /// described as in `effects`: not claimed.
  nlohmann::json refit_rejected;
  /// Selection::pairs: each {candidates: [two descriptions with the joint parameters], score,
  /// heldout_gain, heldout_gain_per_training_run, adds_to_second_alone, adds_to_first_alone,
  /// admissible}.
  nlohmann::json pairs;
};

/// The description of a fitted candidate in calibration.json (`effects`, `runners_up`): kind, name,
/// location, parameters (a per-run air's per training run, with where its air came from), scores,
/// `unphysical` when it is. A claimed air's test-run sink tables are added by calibrate().
nlohmann::json effect_json(const Catalogue& cat, const EffectFit& fit, bool claimed);

/// calibration.json's `ambiguous`: per Selection::ambiguous, {candidates: [two effect_json],
/// score_difference, spread, distinguishing_channel {channel, rms_difference_sigmas}, hint}.
nlohmann::json ambiguity_json(const Catalogue& cat, const Selection& selection);

/// What measurement would tell candidates of kinds `a` and `b` apart (`a_candidate` and
/// `b_candidate` their descriptions as in CalibrationResult::effects).
std::string telling_apart(const nlohmann::json& a_candidate, const nlohmann::json& b_candidate);

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
