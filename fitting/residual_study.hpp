// What a fitted thermal-error model lacks, traced from its residual on held-out training data.
// The study starts from a baseline model (in calibrate without --case, the one fit --data chooses
// by blocked cross-validation: ridge or least squares on the temperature rises, possibly with
// their first-order lags and the speed, or no compensation) fitted on training segments;
// candidate terms built from what a measured run holds (speed, time, temperatures) are added one
// at a time, each scored by the share of the leave-one-segment-out residual it removes, and
// claimed only when that share, less a penalty per added coefficient, beats the best share reached
// by surrogates of the same term: the same amplitude spectrum with random phases (as smooth and as
// strong, with no timing relation to the residual). A circular shift would not do: a 50 % on/off
// duty shifted by half a cycle is the same regressor with its sign flipped.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/enum_names.hpp"
#include "fitting/features.hpp"
#include "fitting/linear.hpp"
#include "fitting/models.hpp"
#include "fitting/segments.hpp"

namespace tt::fitting {

/// A candidate term of the residual study (not calibration::EffectKind, the model-based
/// calibration's effects on the machine).
enum class TermKind {
  /// a drift that follows the current speed: n and n² (centrifugal growth, probe runout)
  speed_dependent_offset,
  /// heat input through a first-order lag: low_pass(n, τ)
  lagged_speed,
  /// the error lags the model's temperatures: low_pass(ΔT_k, τ) of each model sensor
  lag,
  /// the ambient sensor's increment (when the run names one)
  ambient_temperature,
  /// a temperature the model does not read: ΔT of one more sensor
  missing_sensor,
  /// drift linear in the time since the segment started
  drift_in_time,
};

/// The terms' names in calibration.json and reports.
inline constexpr std::array<core::Named<TermKind>, 6> kTermKindNames{{
    {TermKind::speed_dependent_offset, "speed_dependent_offset"},
    {TermKind::lagged_speed, "lagged_speed"},
    {TermKind::lag, "lag"},
    {TermKind::ambient_temperature, "ambient_temperature"},
    {TermKind::missing_sensor, "missing_sensor"},
    {TermKind::drift_in_time, "drift_in_time"},
}};
static_assert(core::one_to_one(kTermKindNames));

/// The term's name in kTermKindNames.
std::string term_kind_name(TermKind kind);

/// One candidate term with its setting.
struct EffectTerm {
  TermKind kind = TermKind::drift_in_time;
  /// low-pass time constant of lagged_speed and lag [s]
  double time_constant = 0.0;
  /// temperature column of missing_sensor and ambient_temperature
  int sensor = -1;
};

/// The model a study starts from: a linear model's form (its spec: least squares, ridge or
/// distributed lag with its ridge strength, or no compensation) and its regressors. Terms are
/// fitted jointly with the baseline's regressors under the baseline's ridge strength (the 3σ
/// criterion of the standard's least squares applies to the baseline alone). No compensation has
/// no regressors and no intercept: the terms added to it are fitted without one.
struct Baseline {
  ModelSpec spec;
  /// empty for no compensation
  FeatureMap features;
};

/// The baseline of a fitted linear model (e.g. blocked_evaluation's choice); throws DataError for
/// a model that is not linear in its regressors (PPR, the network).
Baseline baseline_of(const FittedModel& model);

/// The standard's least squares (no 3σ criterion) on the temperature rises of `sensors`.
Baseline least_squares_baseline(const std::vector<int>& sensors,
                                const std::vector<std::string>& sensor_names);

/// The temperature columns the baseline reads (what a lag filters and a missing sensor is not).
const std::vector<int>& baseline_sensors(const Baseline& baseline);

/// A linear model: intercept (none on a no-compensation baseline), the baseline's regressors,
/// then the regressors of each term in order.
struct TermModel {
  int target = 0;
  Baseline baseline;
  std::vector<EffectTerm> terms;
  /// intercept [m] and coefficients [m per regressor unit: K, rpm (the baseline's speed), krpm,
  /// krpm², h]
  LinearFit fit;
};

/// #samples x #regressors of a model on a segment, without the intercept column.
Eigen::MatrixXd term_regressors(const Baseline& baseline, const std::vector<EffectTerm>& terms,
                                const Segment& segment);

/// Names of term_regressors' columns, e.g. "dT[t5]", "lp600s(d[speed_rpm])", "speed_krpm",
/// "lp3600s(speed_krpm)".
std::vector<std::string> term_regressor_names(const Baseline& baseline,
                                              const std::vector<EffectTerm>& terms,
                                              const std::vector<std::string>& sensor_names);

/// #samples predicted error [m] of the model's target on a segment.
Eigen::VectorXd term_prediction(const TermModel& model, const Segment& segment);

/// The model fitted on the segments' target column (all rows stacked). With no terms it is the
/// baseline exactly as fitting::fitted_model fits it (so calibrate's before is fit --data's
/// chosen model); with terms, the joint fit under the baseline's ridge strength.
TermModel fitted_term_model(const std::vector<Segment>& segments, int target,
                            const Baseline& baseline, const std::vector<EffectTerm>& terms);

struct ResidualStudyOptions {
  /// time constants tried for lag and lagged_speed [s]
  std::vector<double> time_constants{900.0, 1800.0, 3600.0, 7200.0, 14400.0};
  /// phase-randomised surrogates per tested term; the claim threshold is their largest share (19
  /// copies: a 5 % chance that a term with no relation beats all of them)
  int null_draws = 19;
  /// share of the held-out residual a term must explain per coefficient it adds, beyond the null
  double penalty_per_parameter = 0.01;
  /// at most this many effects
  int max_effects = 4;
  /// the mean per-segment held-out gain of a claimed term (nested: its setting searched without
  /// the segment) must exceed this many standard errors (a gain that one segment carries, or that
  /// picking the best of many settings makes, is not claimed)
  double min_gain_t = 2.0;
  /// temperature column of the ambient sensor, -1 when the run names none
  int ambient_sensor = -1;
  /// master seed of the surrogates
  std::uint64_t seed = 1;
};

/// One tested term: what it explains and what chance explains.
struct Effect {
  EffectTerm term;
  /// coefficients it adds
  int parameters = 0;
  /// share of the held-out (leave-one-segment-out) training residual sum of squares it removes
  /// from the model before it (the step it was tested at)
  double step_fraction = 0.0;
  /// the same reduction as a share of the baseline's held-out residual (comparable across effects)
  double explained_fraction = 0.0;
  /// the largest step share reached by its surrogates, never below 0 (the noise threshold); NaN
  /// when not computed (its step share was below the penalty already)
  double null_fraction = 0.0;
  /// the held-out (leave-one-segment-out) RMS of the training segments before and with the
  /// term [m]; NaN when not computed
  double heldout_rms_before = std::numeric_limits<double>::quiet_NaN();
  double heldout_rms_after = std::numeric_limits<double>::quiet_NaN();
  /// per-segment held-out gains, nested: for each segment the setting (time constant, sensor) is
  /// searched on the other segments' held-out residual only; their mean over its standard error,
  /// and how many are positive
  double gain_t = std::numeric_limits<double>::quiet_NaN();
  int segments_improved = 0;
  /// step_fraction − penalty·parameters > null_fraction and gain_t > min_gain_t
  bool claimed = false;
};

struct ChannelStudy {
  int target = 0;
  std::string target_name;
  /// the baseline, fitted on all training segments
  TermModel before;
  /// the baseline with the claimed effects, fitted on all training segments
  TermModel after;
  /// claimed effects in the order they were added
  std::vector<Effect> effects;
  /// per step, the best term of every kind tried (claimed or not), largest step share first; the
  /// last step is where the study stopped
  std::vector<std::vector<Effect>> steps;
  /// leave-one-segment-out residual sum of squares of the training segments [m²]
  double heldout_rss_before = 0.0;
  double heldout_rss_after = 0.0;
};

/// The study for one error column of at least 2 training segments, from `baseline`. Throws
/// DataError on fewer segments or inconsistent ones.
ChannelStudy residual_study(const std::vector<Segment>& training, int target,
                            const Baseline& baseline, const ResidualStudyOptions& options);

/// Leave-one-segment-out residual sum of squares [m²] of the model (baseline, terms), each fold
/// fitted as fitted_term_model fits it with terms (the baseline's ridge on the fold's own column
/// scales; no 3σ criterion).
double heldout_rss(const std::vector<Segment>& segments, int target, const Baseline& baseline,
                   const std::vector<EffectTerm>& terms);

}  // namespace tt::fitting
