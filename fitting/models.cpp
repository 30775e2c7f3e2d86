#include "fitting/models.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "core/errors.hpp"

namespace tt::fitting {

namespace {

FeatureMap feature_map(const ModelSpec& spec, const Group& group, const std::vector<int>& sensors) {
  FeatureMap map;
  map.sensors = sensors;
  for (int s : sensors) {
    if (s < 0 || s >= static_cast<int>(group.sensor_names.size()))
      throw core::DataError("sensor column " + std::to_string(s) + "; expected an index in [0, " +
                            std::to_string(group.sensor_names.size()) + ")");
    map.sensor_names.push_back(group.sensor_names[static_cast<std::size_t>(s)]);
  }
  if (spec.kind == ModelKind::distributed_lag && spec.time_constants.empty())
    throw core::DataError(
        "distributed_lag model with no time constants; expected at least "
        "one, e.g. {1800} s");
  if (spec.kind == ModelKind::distributed_lag || spec.kind == ModelKind::cnn_bigru_attention)
    map.time_constants = spec.time_constants;
  if (spec.use_inputs)
    for (std::size_t c = 0; c < group.input_names.size(); ++c) {
      map.inputs.push_back(static_cast<int>(c));
      map.input_names.push_back(group.input_names[c]);
    }
  return map;
}

using Body = std::variant<LinearFit, PprModel, torchnet::Network>;

/// The median interval between consecutive rows of the groups [s]; 0 with fewer than two rows.
double median_interval(const std::vector<Group>& groups) {
  std::vector<double> dt;
  for (const Group& g : groups)
    for (Eigen::Index i = 1; i < g.time.size(); ++i) dt.push_back(g.time(i) - g.time(i - 1));
  if (dt.empty()) return 0.0;
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
  return dt[dt.size() / 2];
}

/// Samples between two entries of a network window: window_span_s over (window_steps − 1), in
/// units of the median sampling interval.
int window_stride(const NetworkSettings& settings, double median) {
  if (!(median > 0.0) || !(settings.window_span_s > 0.0)) return 1;
  const double entries = std::max(1, settings.options.window_steps - 1);
  return std::max(1, static_cast<int>(std::lround(settings.window_span_s / entries / median)));
}

Eigen::MatrixXd selected_rows(const Eigen::MatrixXd& m, const std::vector<Eigen::Index>& rows) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()), m.cols());
  for (std::size_t i = 0; i < rows.size(); ++i)
    out.row(static_cast<Eigen::Index>(i)) = m.row(rows[i]);
  return out;
}

/// Ridge strengths the network's linear skip is chosen among: the measured-data candidates' grid.
constexpr std::array<double, 8> kSkipLambdas{1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0};
/// Sequences under which (fewer) the skip chooses its own strength: fewer than the blocked
/// evaluation's folds ever hold.
constexpr std::size_t kSkipSequenceBlocks = 3;
/// Time blocks (at least) that choose the skip's own strength.
constexpr int kSkipBlocks = 5;

/// #rows block index of the stacked rows of the sequences: each sequence cut into equal
/// contiguous time blocks, at least kSkipBlocks in all (skip_lambda's blocks).
std::vector<int> skip_blocks(const std::vector<Eigen::MatrixXd>& xs) {
  const int per = (kSkipBlocks + static_cast<int>(xs.size()) - 1) / static_cast<int>(xs.size());
  std::vector<int> out;
  int first = 0;
  for (const auto& x : xs) {
    const Eigen::Index n = x.rows();
    const int parts = static_cast<int>(std::min<Eigen::Index>(per, std::max<Eigen::Index>(1, n)));
    for (Eigen::Index i = 0; i < n; ++i) out.push_back(first + static_cast<int>(i * parts / n));
    first += parts;
  }
  return out;
}

/// The ridge strength of kSkipLambdas whose fit, each block held out in turn and fitted on the
/// others, gives the lowest mean S² (residual variance) over the held-out blocks: the criterion
/// of the blocked evaluation, one level down.
double skip_lambda(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                   const std::vector<int>& block) {
  const int blocks = *std::max_element(block.begin(), block.end()) + 1;
  double best = kSkipLambdas.front(), best_score = std::numeric_limits<double>::infinity();
  for (double lambda : kSkipLambdas) {
    double score = 0.0;
    for (int b = 0; b < blocks; ++b) {
      std::vector<Eigen::Index> in, out;
      for (std::size_t r = 0; r < block.size(); ++r)
        (block[r] == b ? out : in).push_back(static_cast<Eigen::Index>(r));
      if (out.size() < 2 || static_cast<Eigen::Index>(in.size()) < x.cols() + 3) continue;
      const LinearFit f = linear_fit(selected_rows(x, in), selected_rows(y, in), lambda);
      const double s =
          residual_std(selected_rows(y, out) - linear_prediction(f, selected_rows(x, out)));
      score += s * s;
    }
    if (score < best_score) {
      best_score = score;
      best = lambda;
    }
  }
  return best;
}

/// The network's linear skip: per output, the ridge fit on every row of the fitting and
/// validation sequences (in the network's input and output units). Its strength is `lambda` (the
/// spec's, chosen by the blocked evaluation on speed cycles or runs) when the training is given as
/// at least kSkipSequenceBlocks sequences, as in every fold of that evaluation; given fewer (one
/// continuous run refitted outside a window, its features referenced to the run's start: a regime
/// that lambda was not chosen for) it is the strength of kSkipLambdas that predicts held-out time
/// blocks of the sequences best (skip_lambda).
torchnet::LinearSkip linear_skip(const torchnet::Sequences& fit,
                                 const torchnet::Sequences& validation, double lambda) {
  std::vector<Eigen::MatrixXd> xs = fit.inputs, ys = fit.outputs;
  xs.insert(xs.end(), validation.inputs.begin(), validation.inputs.end());
  ys.insert(ys.end(), validation.outputs.begin(), validation.outputs.end());
  Eigen::Index rows = 0;
  for (const auto& x : xs) rows += x.rows();
  Eigen::MatrixXd x(rows, xs.front().cols()), y(rows, ys.front().cols());
  for (std::size_t g = 0, r = 0; g < xs.size(); r += static_cast<std::size_t>(xs[g].rows()), ++g) {
    x.middleRows(static_cast<Eigen::Index>(r), xs[g].rows()) = xs[g];
    y.middleRows(static_cast<Eigen::Index>(r), ys[g].rows()) = ys[g];
  }
  const bool own_strength = xs.size() < kSkipSequenceBlocks;
  const std::vector<int> block = own_strength ? skip_blocks(xs) : std::vector<int>{};
  torchnet::LinearSkip skip{Eigen::VectorXd(y.cols()), Eigen::MatrixXd(y.cols(), x.cols()),
                            Eigen::VectorXd(y.cols())};
  for (Eigen::Index k = 0; k < y.cols(); ++k) {
    const double strength = own_strength ? skip_lambda(x, y.col(k), block) : lambda;
    const LinearFit f = linear_fit(x, y.col(k), strength);
    skip.intercept(k) = f.intercept;
    skip.weights.row(k) = f.coefficients.transpose();
    skip.ridge_lambda(k) = strength;
  }
  return skip;
}

/// The network of `spec` trained on sequences, with its linear skip when the spec asks for one.
torchnet::Network trained_on(const ModelSpec& spec, const torchnet::NetworkOptions& options,
                             const torchnet::Sequences& fit,
                             const torchnet::Sequences& validation) {
  if (!spec.network.linear_skip) return torchnet::trained_network(fit, validation, options);
  return torchnet::trained_network(fit, validation, options,
                                   linear_skip(fit, validation, spec.ridge_lambda));
}

torchnet::Network network_fit(const ModelSpec& spec, const torchnet::NetworkOptions& options,
                              const FeatureMap& features, const std::vector<Group>& groups,
                              const std::vector<int>& targets) {
  // With three or more groups the last one stops the training early; with fewer, the adapter
  // holds out the last fifth of each group.
  torchnet::Sequences fit, validation;
  const bool hold_last = groups.size() >= 3;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    torchnet::Sequences& s = hold_last && g + 1 == groups.size() ? validation : fit;
    s.inputs.push_back(feature_matrix(features, groups[g]));
    Eigen::MatrixXd y(groups[g].error.rows(), static_cast<Eigen::Index>(targets.size()));
    for (std::size_t k = 0; k < targets.size(); ++k)
      y.col(static_cast<Eigen::Index>(k)) = groups[g].error.col(targets[k]);
    s.outputs.push_back(std::move(y));
  }
  return trained_on(spec, options, fit, validation);
}

Body body_fit(const ModelSpec& spec, const Eigen::MatrixXd& x, const Eigen::VectorXd& y) {
  switch (spec.kind) {
    case ModelKind::no_compensation:
      return LinearFit{0.0, Eigen::VectorXd::Zero(x.cols())};
    case ModelKind::least_squares:
      return linear_fit(x, y, 0.0);
    case ModelKind::ridge:
    case ModelKind::distributed_lag:
      return linear_fit(x, y, spec.ridge_lambda);
    case ModelKind::projection_pursuit:
      return ppr_fit(x, y, spec.ppr);
    case ModelKind::cnn_bigru_attention:
      break;  // trained on sequences (network_fit), never on stacked rows
  }
  throw core::DataError("model kind '" + kind_name(spec.kind) + "' cannot be fitted on rows");
}

Eigen::VectorXd body_prediction(const Body& body, const Eigen::MatrixXd& x, int output = 0) {
  if (const auto* linear = std::get_if<LinearFit>(&body)) return linear_prediction(*linear, x);
  if (const auto* network = std::get_if<torchnet::Network>(&body))
    return network->prediction(x).col(output);  // x: one group's rows in time order
  return ppr_prediction(std::get<PprModel>(body), x);
}

}  // namespace

std::string kind_name(ModelKind kind) {
  return std::string(core::name_in(kModelKindNames, kind));
}

std::string model_label(const ModelSpec& spec) {
  std::ostringstream out;
  out << kind_name(spec.kind);
  switch (spec.kind) {
    case ModelKind::no_compensation:
      break;
    case ModelKind::least_squares:
      if (!spec.reject_gross_errors) out << "(no_3sigma)";
      break;
    case ModelKind::ridge:
      out << "(lambda=" << spec.ridge_lambda << ")";
      break;
    case ModelKind::projection_pursuit:
      out << "(degree=" << spec.ppr.degree << ",max_terms=" << spec.ppr.max_terms << ")";
      break;
    case ModelKind::distributed_lag:
      out << "(tau_s=";
      for (std::size_t t = 0; t < spec.time_constants.size(); ++t)
        out << (t ? "/" : "") << spec.time_constants[t];
      out << ",lambda=" << spec.ridge_lambda << ")";
      break;
    case ModelKind::cnn_bigru_attention:
      out << "(window=" << spec.network.options.window_steps << "x" << spec.network.window_span_s
          << "s,conv=" << spec.network.options.conv_channels
          << ",gru=" << spec.network.options.gru_layers << "x" << spec.network.options.gru_hidden;
      if (spec.network.options.weight_decay > 0.0)
        out << ",wd=" << spec.network.options.weight_decay;
      if (!spec.time_constants.empty()) {
        out << ",tau_s=";
        for (std::size_t t = 0; t < spec.time_constants.size(); ++t)
          out << (t ? "/" : "") << spec.time_constants[t];
      }
      if (spec.network.linear_skip) out << ",linear_skip_lambda=" << spec.ridge_lambda;
      out << ",seed=" << spec.network.options.seed << ")";
      break;
  }
  if (spec.use_inputs && spec.kind != ModelKind::no_compensation) out << "+inputs";
  return out.str();
}

int coefficient_count(const ModelSpec& spec, int sensors, int inputs) {
  const int base = sensors + (spec.use_inputs ? inputs : 0);
  switch (spec.kind) {
    case ModelKind::no_compensation:
      return 0;
    case ModelKind::least_squares:
    case ModelKind::ridge:
      return base;
    case ModelKind::distributed_lag:
      return base * (1 + static_cast<int>(spec.time_constants.size()));
    case ModelKind::projection_pursuit:
      return base * std::max(1, spec.ppr.max_terms);
    case ModelKind::cnn_bigru_attention:
      // Thousands of weights: after every linear model in the order of simplicity (ties).
      return std::numeric_limits<int>::max() / 2;
  }
  return base;
}

namespace {

/// A model of `spec` on `target` with its features and groups named, not yet fitted.
FittedModel unfitted_model(const ModelSpec& spec, const std::vector<Group>& groups,
                           const std::vector<int>& sensors, int target) {
  if (sensors.empty())
    throw core::DataError("model '" + model_label(spec) +
                          "' with no sensors; expected at least one temperature column");
  const Group& first = groups.front();
  if (target < 0 || target >= static_cast<int>(first.target_names.size()))
    throw core::DataError("target " + std::to_string(target) + "; expected an index in [0, " +
                          std::to_string(first.target_names.size()) + ")");
  FittedModel model;
  model.spec = spec;
  model.features = feature_map(spec, first, sensors);
  model.target = target;
  model.target_name = first.target_names[static_cast<std::size_t>(target)];
  for (const Group& g : groups) model.fitted_on.push_back(g.name);
  return model;
}

/// One network trained on `targets` at once: a model per target sharing it.
std::vector<FittedModel> network_models(const ModelSpec& spec, const std::vector<Group>& groups,
                                        const std::vector<int>& sensors,
                                        const std::vector<int>& targets) {
  std::vector<FittedModel> models;
  for (int t : targets) models.push_back(unfitted_model(spec, groups, sensors, t));
  torchnet::NetworkOptions options = spec.network.options;
  options.sample_interval_s = median_interval(groups);
  options.window_stride = window_stride(spec.network, options.sample_interval_s);
  const torchnet::Network network =
      network_fit(spec, options, models.front().features, groups, targets);
  int samples = 0;
  for (const Group& g : groups) samples += static_cast<int>(g.time.size());
  for (std::size_t k = 0; k < models.size(); ++k) {
    models[k].body = network;
    models[k].output = static_cast<int>(k);
    models[k].rejection.samples = samples;
    models[k].rejection.passes = 1;
  }
  return models;
}

}  // namespace

FittedModel fitted_model(const ModelSpec& spec, const std::vector<Group>& groups,
                         const std::vector<int>& sensors, int target) {
  require_consistent_groups(groups);
  if (spec.kind == ModelKind::cnn_bigru_attention)
    return network_models(spec, groups, sensors, {target}).front();
  FittedModel model = unfitted_model(spec, groups, sensors, target);

  const StackedRows rows = stacked_rows(model.features, groups, target);
  const Eigen::Index n = rows.error.size();
  const Eigen::Index minimum = rows.features.cols() + 3;
  std::vector<Eigen::Index> kept(static_cast<std::size_t>(n));
  std::iota(kept.begin(), kept.end(), Eigen::Index{0});
  model.rejection.samples = static_cast<int>(n);
  // The 3σ loop ends when a fit leaves no residual beyond 3σ; 100 passes is far more than the few
  // a campaign with gross errors needs and only guards against a pathological cycle.
  for (int pass = 1; pass <= 100; ++pass) {
    const Eigen::MatrixXd x = selected_rows(rows.features, kept);
    Eigen::VectorXd y(static_cast<Eigen::Index>(kept.size()));
    for (std::size_t i = 0; i < kept.size(); ++i)
      y(static_cast<Eigen::Index>(i)) = rows.error(kept[i]);
    model.body = body_fit(spec, x, y);
    model.rejection.passes = pass;
    if (!spec.reject_gross_errors || spec.kind == ModelKind::no_compensation) break;
    const Eigen::VectorXd residual = y - body_prediction(model.body, x);
    const double limit = 3.0 * residual_std(residual);
    std::vector<Eigen::Index> next;
    for (std::size_t i = 0; i < kept.size(); ++i)
      if (std::abs(residual(static_cast<Eigen::Index>(i))) <= limit) next.push_back(kept[i]);
    if (next.size() == kept.size()) break;
    if (static_cast<Eigen::Index>(next.size()) < minimum)
      throw core::DataError("3σ rejection left " + std::to_string(next.size()) + " of " +
                            std::to_string(n) + " samples for model '" + model_label(spec) +
                            "'; expected at least " + std::to_string(minimum) +
                            "; hint: check the data for a broken sensor");
    kept = std::move(next);
  }
  model.rejection.rejected = static_cast<int>(n - static_cast<Eigen::Index>(kept.size()));
  std::vector<bool> is_kept(static_cast<std::size_t>(n), false);
  for (Eigen::Index row : kept) is_kept[static_cast<std::size_t>(row)] = true;
  for (Eigen::Index row = 0; row < n; ++row)
    if (!is_kept[static_cast<std::size_t>(row)])
      model.rejection.rejected_rows.push_back(static_cast<int>(row));
  return model;
}

std::vector<FittedModel> fitted_network_models(const ModelSpec& spec,
                                               const std::vector<Group>& groups,
                                               const std::vector<int>& sensors,
                                               const std::vector<int>& targets) {
  require_consistent_groups(groups);
  if (spec.kind != ModelKind::cnn_bigru_attention)
    throw core::DataError("one model for several targets of kind '" + kind_name(spec.kind) +
                          "'; expected cnn_bigru_attention (a network with an output per target)");
  if (targets.empty())
    throw core::DataError("a network for no targets; expected at least one target column");
  for (std::size_t i = 0; i < targets.size(); ++i)
    for (std::size_t j = i + 1; j < targets.size(); ++j)
      if (targets[i] == targets[j])
        throw core::DataError("target " + std::to_string(targets[i]) +
                              " listed twice for one network; expected each target once");
  return network_models(spec, groups, sensors, targets);
}

Eigen::VectorXd refitted_prediction(const FittedModel& chosen, const Group& group,
                                    const std::vector<bool>& fit_row) {
  if (static_cast<Eigen::Index>(fit_row.size()) != group.time.size())
    throw core::DataError("refit mask of " + std::to_string(fit_row.size()) + " rows on group '" +
                          group.name + "' of " + std::to_string(group.time.size()) + " samples");
  const Eigen::MatrixXd x = feature_matrix(chosen.features, group);
  const Eigen::VectorXd e = group.error.col(chosen.target);
  if (const auto* network = std::get_if<torchnet::Network>(&chosen.body)) {
    torchnet::Sequences fit;
    for (Eigen::Index i = 0; i < x.rows();) {
      Eigen::Index j = i;
      while (j < x.rows() && fit_row[static_cast<std::size_t>(j)]) ++j;
      if (j - i >= 2) {
        fit.inputs.push_back(x.middleRows(i, j - i));
        fit.outputs.push_back(e.segment(i, j - i));
      }
      i = j + 1;
    }
    return trained_on(chosen.spec, network->options(), fit, {}).prediction(x).col(0);
  }
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    if (fit_row[static_cast<std::size_t>(i)]) rows.push_back(i);
  Eigen::VectorXd y(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) y(static_cast<Eigen::Index>(i)) = e(rows[i]);
  return body_prediction(body_fit(chosen.spec, selected_rows(x, rows), y), x);
}

ModelSpec network_spec(const torchnet::NetworkOptions& options, double window_span_s,
                       const std::string& sensor_method) {
  ModelSpec spec;
  spec.kind = ModelKind::cnn_bigru_attention;
  spec.network.options = options;
  spec.network.window_span_s = window_span_s;
  spec.sensor_method = sensor_method;
  spec.reject_gross_errors = false;
  return spec;
}

Eigen::VectorXd predicted_error(const FittedModel& model, const Group& group) {
  for (std::size_t k = 0; k < model.features.sensors.size(); ++k) {
    const auto column = static_cast<std::size_t>(model.features.sensors[k]);
    const std::string found =
        column < group.sensor_names.size() ? "'" + group.sensor_names[column] + "'" : "missing";
    if (found != "'" + model.features.sensor_names[k] + "'")
      throw core::DataError("group '" + group.name + "' temperature column " +
                            std::to_string(column) + " is " + found + "; the model expects '" +
                            model.features.sensor_names[k] +
                            "'; hint: predict on groups of the campaign the model was fitted on");
  }
  return body_prediction(model.body, feature_matrix(model.features, group), model.output);
}

Accuracy model_accuracy(const FittedModel& model, const std::vector<Group>& groups) {
  std::vector<double> s;
  for (const Group& g : groups) {
    if (model.target >= g.error.cols())
      throw core::DataError("group '" + g.name + "' has " + std::to_string(g.error.cols()) +
                            " targets; the model predicts target " + std::to_string(model.target));
    s.push_back(residual_std(g.error.col(model.target) - predicted_error(model, g)));
  }
  return accuracy(s);
}

std::vector<int> sensors_by_correlation(const std::vector<Group>& groups, int target, int count) {
  require_consistent_groups(groups);
  const int sensors = static_cast<int>(groups.front().sensor_names.size());
  if (count < 1 || count > sensors)
    throw core::DataError("sensor count " + std::to_string(count) + "; expected 1.." +
                          std::to_string(sensors) + " (the standard recommends 2 to 4)");
  FeatureMap all;
  all.sensors.resize(static_cast<std::size_t>(sensors));
  std::iota(all.sensors.begin(), all.sensors.end(), 0);
  all.sensor_names = groups.front().sensor_names;
  const StackedRows rows = stacked_rows(all, groups, target);
  const Eigen::VectorXd e = rows.error.array() - rows.error.mean();
  std::vector<double> score(static_cast<std::size_t>(sensors));
  for (int k = 0; k < sensors; ++k) {
    const Eigen::VectorXd t = rows.features.col(k).array() - rows.features.col(k).mean();
    const double denominator = t.norm() * e.norm();
    score[static_cast<std::size_t>(k)] = denominator > 0.0 ? std::abs(t.dot(e)) / denominator : 0.0;
  }
  std::vector<int> order(static_cast<std::size_t>(sensors));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return score[static_cast<std::size_t>(a)] > score[static_cast<std::size_t>(b)];
  });
  order.resize(static_cast<std::size_t>(count));
  return order;
}

std::vector<ModelSpec> default_model_candidates() {
  std::vector<ModelSpec> specs;
  specs.push_back(ModelSpec{});
  for (double lambda : {1e-4, 1e-3, 1e-2, 1e-1}) {
    ModelSpec s;
    s.kind = ModelKind::ridge;
    s.ridge_lambda = lambda;
    specs.push_back(s);
  }
  for (auto [degree, terms] : {std::pair{2, 2}, std::pair{3, 2}, std::pair{3, 4}}) {
    ModelSpec s;
    s.kind = ModelKind::projection_pursuit;
    s.ppr.degree = degree;
    s.ppr.max_terms = terms;
    specs.push_back(s);
  }
  for (const std::vector<double>& taus : std::vector<std::vector<double>>{
           {600.0}, {1800.0}, {5400.0}, {900.0, 3600.0}, {600.0, 2400.0, 9600.0}}) {
    ModelSpec s;
    s.kind = ModelKind::distributed_lag;
    s.time_constants = taus;
    s.ridge_lambda = 1e-6;
    specs.push_back(s);
  }
  return specs;
}

}  // namespace tt::fitting
