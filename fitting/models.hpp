// Thermal-error models behind one interface: fit on groups, get a model value; predict on a group.
// Every model reads the increments ΔT_k = T_k − T_k0 of its sensors, each group relative to its
// own first reading (the standard's formula 2).
#pragma once

#include <Eigen/Dense>
#include <string>
#include <variant>
#include <vector>

#include "core/enum_names.hpp"
#include "fitting/features.hpp"
#include "fitting/group.hpp"
#include "fitting/linear.hpp"
#include "fitting/metrics.hpp"
#include "fitting/ppr.hpp"
#include "fitting/torch/network.hpp"

namespace tt::fitting {

enum class ModelKind {
  /// E = 0: the machine left uncompensated, the candidate every model must beat on validation
  no_compensation,
  /// the standard's E = β0 + Σ β_k ΔT_k (DB3401/T 326-2024 7.3)
  least_squares,
  /// the same model with standardised ridge shrinkage ridge_lambda
  ridge,
  /// projection pursuit regression with polynomial ridge functions (seed 002)
  projection_pursuit,
  /// linear in ΔT_k and in ΔT_k low-pass filtered with each of time_constants (distributed lags)
  distributed_lag,
  /// the gantry patent's CNN-BiGRU-attention network on windows of the increments (seed 004)
  cnn_bigru_attention,
};

/// Settings of cnn_bigru_attention.
struct NetworkSettings {
  /// the network's structure and training; window_stride is derived from window_span_s
  torchnet::NetworkOptions options;
  /// time an input window spans [s]: the stride between its entries is this over
  /// (window_steps − 1), in samples of the fitting groups' median interval
  double window_span_s = 1800.0;
  /// the network's output is a ridge fit (the spec's ridge_lambda) on the features of the sample
  /// predicted, fitted on every row the training is given (its early-stopping rows included) and
  /// kept fixed, plus the CNN-BiGRU-attention path trained on what that fit leaves
  /// (torchnet::LinearSkip). With the spec's time_constants the features are a distributed-lag
  /// model's: the skip is then that model, and the network's windows read its lagged columns too
  bool linear_skip = false;
};

/// A model type with its settings: one candidate of the selection.
struct ModelSpec {
  ModelKind kind = ModelKind::least_squares;
  /// dimensionless ridge strength (ridge, distributed_lag, a network's linear skip); see linear_fit
  double ridge_lambda = 0.0;
  /// low-pass time constants of distributed_lag [s]; of cnn_bigru_attention too (its input
  /// columns then include the lagged ones)
  std::vector<double> time_constants;
  /// settings of projection_pursuit
  PprOptions ppr;
  /// settings of cnn_bigru_attention
  NetworkSettings network;
  /// when not empty, the selection tries this spec only with sensor sets of this method (a
  /// network is trained on one sensor set, not on every set of every method)
  std::string sensor_method;
  /// the standard's 3σ criterion on the fitting samples (6.2.2): refit and drop samples whose
  /// residual exceeds 3 residual standard deviations until none does (not for the network, which
  /// is trained once)
  bool reject_gross_errors = true;
  /// read the groups' operating inputs (spindle speed) beside the temperatures, as increments
  bool use_inputs = false;
};

/// The kinds' names in fit.json and reports.
inline constexpr std::array<core::Named<ModelKind>, 6> kModelKindNames{{
    {ModelKind::no_compensation, "no_compensation"},
    {ModelKind::least_squares, "least_squares"},
    {ModelKind::ridge, "ridge"},
    {ModelKind::projection_pursuit, "projection_pursuit"},
    {ModelKind::distributed_lag, "distributed_lag"},
    {ModelKind::cnn_bigru_attention, "cnn_bigru_attention"},
}};
static_assert(core::one_to_one(kModelKindNames));

/// The kind's name in kModelKindNames.
std::string kind_name(ModelKind kind);

/// A short label naming the kind and its settings, e.g. "ridge(lambda=0.001)".
std::string model_label(const ModelSpec& spec);

/// How many coefficients (besides the intercept) the spec fits on `sensors` sensors and `inputs`
/// inputs: the order of simplicity that breaks ties of blocked_evaluation (PPR counts as its
/// projections' inputs times its largest number of terms).
int coefficient_count(const ModelSpec& spec, int sensors, int inputs);

/// How many fitting samples the 3σ criterion dropped.
struct GrossErrorRejection {
  int samples = 0;
  int rejected = 0;
  /// rows dropped, counted over the fitting groups' samples stacked in group order
  std::vector<int> rejected_rows;
  /// fits done, the last one with no residual beyond 3σ
  int passes = 0;
};

/// A fitted model: predicts one target from the sensors its feature map names.
struct FittedModel {
  ModelSpec spec;
  FeatureMap features;
  int target = 0;
  std::string target_name;
  /// LinearFit for least_squares, ridge and distributed_lag; PprModel for projection_pursuit;
  /// a Network for cnn_bigru_attention
  std::variant<LinearFit, PprModel, torchnet::Network> body;
  /// cnn_bigru_attention: the network's output that predicts the target (0 unless one network
  /// was trained on several targets at once, fitted_network_models)
  int output = 0;
  GrossErrorRejection rejection;
  /// names of the groups the coefficients were fitted on
  std::vector<std::string> fitted_on;
};

/// Fits `spec` to error column `target` of the groups, reading the temperature columns `sensors`.
/// Throws DataError on inconsistent groups or too few samples.
FittedModel fitted_model(const ModelSpec& spec, const std::vector<Group>& groups,
                         const std::vector<int>& sensors, int target);

/// The gantry patent's one network for every output (seed 004): `spec` (cnn_bigru_attention)
/// trained once on the error columns `targets` together, reading `sensors`. One model per target,
/// in the order of `targets`, all sharing the network (output k predicts targets[k]). Throws
/// DataError as fitted_model does, or when the spec is not a network or a target repeats.
std::vector<FittedModel> fitted_network_models(const ModelSpec& spec,
                                               const std::vector<Group>& groups,
                                               const std::vector<int>& sensors,
                                               const std::vector<int>& targets);

/// The model's form refitted on the rows of `group` where fit_row is true (#samples), predicting
/// every row of the group: #samples [m]. The features run from the group's first reading, so a
/// window of rows can be held out of a continuous run. The network trains on each unbroken run of
/// fitting rows as a sequence.
Eigen::VectorXd refitted_prediction(const FittedModel& chosen, const Group& group,
                                    const std::vector<bool>& fit_row);

/// The network candidate of the patent: cnn_bigru_attention with `options`, tried with the sensor
/// sets of `sensor_method` only.
ModelSpec network_spec(const torchnet::NetworkOptions& options, double window_span_s,
                       const std::string& sensor_method);

/// #samples predicted error of the model's target on a group [m].
Eigen::VectorXd predicted_error(const FittedModel& model, const Group& group);

/// S per group (formula 5), S_M and S_σ of the model on the groups [m].
Accuracy model_accuracy(const FittedModel& model, const std::vector<Group>& groups);

/// The `count` sensors whose increments correlate best (largest |r|, pooled over the groups) with
/// error column `target` (DB3401/T 326-2024 7.1), best first.
std::vector<int> sensors_by_correlation(const std::vector<Group>& groups, int target, int count);

/// The candidates the selection tries when none are given: least squares, ridge at four
/// strengths, three PPR settings and five distributed-lag time-constant sets.
std::vector<ModelSpec> default_model_candidates();

}  // namespace tt::fitting
