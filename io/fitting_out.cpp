#include "io/fitting_out.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <sstream>

#include "core/errors.hpp"
#include "core/text.hpp"
#include "core/units.hpp"
#include "io/atomic_dir.hpp"
#include "io/reports.hpp"

namespace tt::io {

std::string modelling_date_today() {
  using namespace std::chrono;
  sys_seconds now = time_point_cast<seconds>(system_clock::now());
  if (const char* epoch = std::getenv("SOURCE_DATE_EPOCH")) {
    char* end = nullptr;
    const long long s = std::strtoll(epoch, &end, 10);
    if (end != epoch && *end == '\0' && s >= 0) now = sys_seconds(seconds(s));
  }
  const year_month_day day{floor<days>(now)};
  char text[16];
  std::snprintf(text, sizeof text, "%04d-%02u-%02u", static_cast<int>(day.year()),
                static_cast<unsigned>(day.month()), static_cast<unsigned>(day.day()));
  return text;
}

namespace {

using fitting::Evaluation;
using fitting::FittedModel;
using nlohmann::json;

constexpr double um = core::kMicrometresPerMetre;
constexpr double mm = core::kMillimetresPerMetre;

json vector_json(const Eigen::VectorXd& v, double factor = 1.0) {
  json list = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) list.push_back(finite_or_null(v(i) * factor));
  return list;
}

/// S per group keyed by group name, S_M and S_σ, all in µm.
json accuracy_json(const fitting::Accuracy& a, const std::vector<std::string>& groups) {
  json s = json::object();
  for (std::size_t g = 0; g < a.s.size() && g < groups.size(); ++g)
    s[groups[g]] = finite_or_null(a.s[g] * um);
  if (a.s.empty()) return json{{"S_um", s}, {"SM_um", nullptr}, {"S_sigma_um", nullptr}};
  return json{{"S_um", s},
              {"SM_um", finite_or_null(a.sm * um)},
              {"S_sigma_um", finite_or_null(a.s_sigma * um)}};
}

json settings_json(const fitting::ModelSpec& spec) {
  json s{{"reject_gross_errors_3sigma", spec.reject_gross_errors}};
  if (spec.use_inputs) s["inputs"] = true;
  switch (spec.kind) {
    case fitting::ModelKind::no_compensation:
    case fitting::ModelKind::least_squares:
      break;
    case fitting::ModelKind::ridge:
      s["ridge_lambda"] = spec.ridge_lambda;
      break;
    case fitting::ModelKind::distributed_lag:
      s["ridge_lambda"] = spec.ridge_lambda;
      s["time_constants_s"] = spec.time_constants;
      break;
    case fitting::ModelKind::projection_pursuit:
      s["directions"] = spec.ppr.directions;
      s["degree"] = spec.ppr.degree;
      s["max_terms"] = spec.ppr.max_terms;
      s["cluster_epsilon"] = spec.ppr.cluster_epsilon;
      s["relative_error_goal"] = spec.ppr.relative_error_goal;
      s["min_gain"] = spec.ppr.min_gain;
      s["refine"] = spec.ppr.refine;
      s["seed"] = spec.ppr.seed;
      break;
    case fitting::ModelKind::cnn_bigru_attention: {
      const auto& o = spec.network.options;
      s["window_steps"] = o.window_steps;
      s["window_span_s"] = spec.network.window_span_s;
      s["conv_channels"] = o.conv_channels;
      s["kernel_size"] = o.kernel_size;
      s["gru_hidden"] = o.gru_hidden;
      s["gru_layers"] = o.gru_layers;
      s["max_epochs"] = o.max_epochs;
      s["patience"] = o.patience;
      s["batch_size"] = o.batch_size;
      s["learning_rate"] = o.learning_rate;
      s["weight_decay"] = o.weight_decay;
      s["common_output_scale"] = o.common_output_scale;
      s["time_budget_s"] = o.time_budget_s;
      s["seed"] = o.seed;
      s["threads"] = o.threads;
      s["sensor_method"] = spec.sensor_method;
      if (!spec.time_constants.empty()) s["time_constants_s"] = spec.time_constants;
      s["linear_skip"] = spec.network.linear_skip;
      if (spec.network.linear_skip) s["ridge_lambda"] = spec.ridge_lambda;
      break;
    }
  }
  return s;
}

json candidate_json(const Evaluation& e, const fitting::CandidateResult& c) {
  const fitting::SensorSet& set = e.sensor_sets[static_cast<std::size_t>(c.sensor_set)];
  json j{{"method", set.method},
         {"m", set.sensors.size()},
         {"model", fitting::model_label(e.specs[static_cast<std::size_t>(c.spec)])},
         {"kind", fitting::kind_name(e.specs[static_cast<std::size_t>(c.spec)].kind)}};
  if (!c.model) {
    j["status"] = "failed";
    j["failure"] = c.failure;
    return j;
  }
  j["status"] = "ok";
  j["sensors"] = c.model->features.sensor_names;
  j["coefficients"] = model_json(*c.model);
  j["validation"] = accuracy_json(c.validation, e.validation_groups);
  return j;
}

std::string chosen_method(const Evaluation& e) {
  const auto& best = e.selection.candidates[static_cast<std::size_t>(e.selection.best)];
  return e.sensor_sets[static_cast<std::size_t>(best.sensor_set)].method;
}

/// A CSV field, quoted when it holds a separator, a quote or a line break.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char ch : text) quoted += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return quoted + "\"";
}

std::string um_text(double metres) {
  if (!std::isfinite(metres)) return "n/a";
  std::ostringstream out;
  out.precision(4);
  out << metres * um;
  return out.str();
}

/// The names joined by ", ", or "none".
std::string joined(const std::vector<std::string>& names) {
  return names.empty() ? "none" : core::joined(names);
}

/// "E_z [µm] = 1.2 + 3.4·dT[t1] − …" for a linear model; a summary line for PPR.
std::string equation_text(const FittedModel& model) {
  std::ostringstream out;
  out.precision(6);
  if (const auto* linear = std::get_if<fitting::LinearFit>(&model.body)) {
    const std::vector<std::string> names = fitting::feature_names(model.features);
    out << "E_" << model.target_name << " [um] = " << linear->intercept * um;
    for (std::size_t k = 0; k < names.size(); ++k) {
      const double c = linear->coefficients(static_cast<Eigen::Index>(k)) * um;
      out << (c < 0 ? " - " : " + ") << std::abs(c) << " * " << names[k];
    }
    out << "   (coefficients in um/K, dT in K)";
    return out.str();
  }
  if (std::holds_alternative<torchnet::Network>(model.body)) {
    out << "E_" << model.target_name << " = CNN-BiGRU-attention network on windows of dT of "
        << joined(model.features.sensor_names) << " (TorchScript file and JSON record)";
    return out.str();
  }
  const auto& ppr = std::get<fitting::PprModel>(model.body);
  out << "E_" << model.target_name << " [um] = " << ppr.mean * um << " + sum of "
      << ppr.terms.size() << " polynomial ridge functions of projections of "
      << joined(model.features.sensor_names) << " (see the JSON record)";
  return out.str();
}

/// A linear model's intercept and terms [um, um/K].
void add_linear(json& j, const FittedModel& model, const fitting::LinearFit& linear) {
  const std::vector<std::string> names = fitting::feature_names(model.features);
  json terms = json::array();
  for (std::size_t k = 0; k < names.size(); ++k)
    terms.push_back(
        {{"name", names[k]},
         {"um_per_K", finite_or_null(linear.coefficients(static_cast<Eigen::Index>(k)) * um)}});
  j["intercept_um"] = finite_or_null(linear.intercept * um);
  j["terms"] = terms;
}

/// The network's inputs, windows, standardisation, linear skip and training, and how to call
/// its TorchScript file.
void add_network(json& j, const FittedModel& model, const torchnet::Network& net) {
  const auto& o = net.options();
  const auto& r = net.report();
  j["inputs"] = fitting::feature_names(model.features);
  j["output"] = model.output;  // of the network's outputs, the one this target reads
  j["window_steps"] = o.window_steps;
  j["window_stride_samples"] = o.window_stride;
  if (o.sample_interval_s > 0.0) {
    // The time between two entries of a window, for a stream sampled at another rate.
    j["sample_interval_s"] = o.sample_interval_s;
    j["window_spacing_s"] = o.window_stride * o.sample_interval_s;
  }
  j["train_every_samples"] = o.train_every > 0 ? o.train_every : o.window_stride;
  j["input_mean_K"] = vector_json(net.input_mean());
  j["input_scale_K"] = vector_json(net.input_scale());
  j["output_mean_um"] = vector_json(net.output_mean(), um);
  j["output_scale_um"] = vector_json(net.output_scale(), um);
  if (const auto& skip = net.linear_skip()) {
    // The fixed linear part: per output, intercept + Σ weight·input at the sample predicted.
    json outputs = json::array();
    const std::vector<std::string> names = fitting::feature_names(model.features);
    for (Eigen::Index k = 0; k < skip->weights.rows(); ++k) {
      json terms = json::array();
      for (std::size_t c = 0; c < names.size(); ++c)
        terms.push_back(
            {{"name", names[c]},
             {"um_per_K", finite_or_null(skip->weights(k, static_cast<Eigen::Index>(c)) * um)}});
      json o{{"intercept_um", finite_or_null(skip->intercept(k) * um)}, {"terms", terms}};
      if (k < skip->ridge_lambda.size()) o["ridge_lambda"] = skip->ridge_lambda(k);
      outputs.push_back(o);
    }
    j["linear_skip"] = outputs;
  }
  j["training"] = {{"epochs", r.epochs},
                   {"best_epoch", r.best_epoch},
                   {"validation_loss_standardised", finite_or_null(r.validation_loss)},
                   {"seconds", finite_or_null(r.seconds)},
                   {"time_budget_reached", r.budget_reached},
                   {"training_windows", r.training_windows},
                   {"validation_windows", r.validation_windows}};
  j["note"] =
      "TorchScript forward(x): x float32 batch x window_steps x inputs, the increments dT [K] "
      "of the inputs at rows i - (window_steps-1-j)*window_stride_samples (the first row "
      "repeated before the group's start); returns batch x 1 error [m]; standardisation inside, "
      "and the linear skip (buffers skip_w, skip_b; zero without one) applied to the "
      "window's last row";
}

/// The projection pursuit regression's standardisation and ridge functions.
void add_ppr(json& j, const FittedModel& model, const fitting::PprModel& ppr) {
  j["inputs"] = fitting::feature_names(model.features);
  j["input_center_K"] = vector_json(ppr.center);
  j["input_scale_K"] = vector_json(ppr.scale);
  j["mean_um"] = finite_or_null(ppr.mean * um);
  json ridges = json::array();
  for (const fitting::RidgeFunction& r : ppr.terms)
    ridges.push_back({{"direction", vector_json(r.direction)},
                      {"z_low", finite_or_null(r.z_low)},
                      {"z_high", finite_or_null(r.z_high)},
                      {"polynomial_um", vector_json(r.polynomial, um)},
                      {"r_squared", finite_or_null(r.r_squared)},
                      {"cluster_size", r.cluster_size}});
  j["ridge_functions"] = ridges;
  j["note"] =
      "inputs standardised as (dT - center)/scale; z = direction . input; t = (2z - z_low - "
      "z_high)/(z_high - z_low); f(t) = sum polynomial_um[k] t^k, continued along its tangent "
      "outside [-1, 1]; prediction = mean_um + sum f";
}

}  // namespace

json model_json(const FittedModel& model) {
  json j{{"kind", fitting::kind_name(model.spec.kind)},
         {"label", fitting::model_label(model.spec)},
         {"settings", settings_json(model.spec)},
         {"target", model.target_name},
         {"sensors", model.features.sensor_names},
         {"operating_inputs", model.features.input_names},
         {"fitted_on", model.fitted_on},
         {"gross_error_rejection",
          {{"samples", model.rejection.samples},
           {"rejected", model.rejection.rejected},
           {"passes", model.rejection.passes}}}};
  if (const auto* linear = std::get_if<fitting::LinearFit>(&model.body))
    add_linear(j, model, *linear);
  else if (const auto* network = std::get_if<torchnet::Network>(&model.body))
    add_network(j, model, *network);
  else
    add_ppr(j, model, std::get<fitting::PprModel>(model.body));
  return j;
}

json fit_json(const std::vector<Evaluation>& evaluations,
              const std::vector<fitting::SensorCountTable>& sensor_counts) {
  json targets = json::array();
  for (const Evaluation& e : evaluations) {
    json candidates = json::array();
    for (const auto& c : e.selection.candidates) candidates.push_back(candidate_json(e, c));
    const auto& best = e.selection.candidates[static_cast<std::size_t>(e.selection.best)];
    json chosen{{"method", chosen_method(e)},
                {"m", e.model.features.sensors.size()},
                {"model", fitting::model_label(e.model.spec)},
                {"candidate_index", e.selection.best},
                {"validation", accuracy_json(best.validation, e.validation_groups)},
                {"coefficients", model_json(e.model)},
                {"test", accuracy_json(e.test, e.test_groups)}};
    targets.push_back({{"target", e.target_name},
                       {"groups",
                        {{"fitting", e.fitting_groups},
                         {"validation", e.validation_groups},
                         {"test", e.test_groups}}},
                       {"selection_rule",
                        "smallest validation SM (formula 6) over every (sensor set, model); the "
                        "choice is refitted and only then scored on the test groups"},
                       {"candidates", candidates},
                       {"chosen", chosen}});
  }
  json counts = json::array();
  for (const auto& t : sensor_counts) {
    json rows = json::array();
    for (const auto& r : t.rows)
      rows.push_back({{"method", r.method},
                      {"m", r.m},
                      {"model", r.model},
                      {"validation_SM_um", finite_or_null(r.validation_sm * um)},
                      {"test_SM_um", finite_or_null(r.test_sm * um)},
                      {"test_S_sigma_um", finite_or_null(r.test_s_sigma * um)}});
    counts.push_back({{"target", t.target_name},
                      {"required_SM_um", finite_or_null(t.required_sm * um)},
                      {"rows", rows},
                      {"smallest_m_by_validation", t.smallest_m_validation},
                      {"smallest_m_by_test", t.smallest_m_test}});
  }
  json j{{"format", "thermotwin-fit/1"},
         {"metrics",
          "S: formula 5 (N-1) per group; SM: formula 6 (mean of S); S_sigma: formula 7 (K-1), "
          "null for a single group; DB3401/T 326-2024"},
         {"targets", targets}};
  if (!counts.empty()) j["sensor_count"] = counts;
  return j;
}

void write_fit_json(const std::filesystem::path& path, const std::vector<Evaluation>& evaluations,
                    const std::vector<fitting::SensorCountTable>& sensor_counts) {
  write_file_atomically(path, fit_json(evaluations, sensor_counts).dump(2) + "\n");
}

json modelling_record_json(const ModellingConditions& c,
                           const std::vector<Evaluation>& evaluations) {
  json models = json::array();
  for (const Evaluation& e : evaluations)
    models.push_back({{"target", e.target_name},
                      {"placement_method", chosen_method(e)},
                      {"equation", equation_text(e.model)},
                      {"model", model_json(e.model)},
                      {"groups",
                       {{"fitting", e.fitting_groups},
                        {"validation", e.validation_groups},
                        {"test", e.test_groups}}},
                      {"test_accuracy", accuracy_json(e.test, e.test_groups)}});
  json j{
      {"standard", "DB3401/T 326-2024, section 8 modelling result"},
      {"machine",
       {{"model", c.machine_model},
        {"number", c.machine_number},
        {"travel_mm", {{"x", c.travel_x * mm}, {"y", c.travel_y * mm}, {"z", c.travel_z * mm}}}}},
      {"modelling_date", c.modelling_date},
      {"initial_ambient_temperature_degC",
       finite_or_null(c.initial_ambient_temperature - core::kCelsiusOffset)},
      {"max_spindle_speed_rpm",
       finite_or_null(c.max_spindle_speed * 60.0 / (2.0 * std::numbers::pi))},
      {"max_feed_rate_mm_per_min", finite_or_null(c.max_feed_rate * mm * 60.0)},
      {"models", models},
      {"compensation",
       "the CNC shifts the work origin by minus the predicted error; refresh the model each "
       "quarter"}};
  if (c.cutting)
    j["cutting"] = {{"tool", c.cutting->tool},
                    {"workpiece_material", c.cutting->workpiece_material},
                    {"workpiece_size", c.cutting->workpiece_size},
                    {"cutting_speed_m_per_min", finite_or_null(c.cutting->cutting_speed * 60.0)},
                    {"feed_mm_per_rev", finite_or_null(c.cutting->feed * mm)},
                    {"depth_of_cut_mm", finite_or_null(c.cutting->depth_of_cut * mm)}};
  return j;
}

std::string modelling_record_markdown(const ModellingConditions& c,
                                      const std::vector<Evaluation>& evaluations) {
  const json j = modelling_record_json(c, evaluations);
  std::ostringstream out;
  out << "# Thermal-error modelling record (DB3401/T 326-2024, section 8)\n\n";
  out << "| item | value |\n| --- | --- |\n";
  out << "| machine model | " << c.machine_model << " |\n";
  out << "| machine number | " << c.machine_number << " |\n";
  out << "| travel X / Y / Z [mm] | " << c.travel_x * mm << " / " << c.travel_y * mm << " / "
      << c.travel_z * mm << " |\n";
  out << "| modelling date | " << c.modelling_date << " |\n";
  out << "| initial ambient temperature [°C] | "
      << c.initial_ambient_temperature - core::kCelsiusOffset << " |\n";
  out << "| maximum spindle speed [rpm] | " << j["max_spindle_speed_rpm"].dump() << " |\n";
  out << "| maximum feed rate [mm/min] | " << j["max_feed_rate_mm_per_min"].dump() << " |\n";
  if (c.cutting) {
    out << "| cutting tool | " << c.cutting->tool << " |\n";
    out << "| workpiece material and size | " << c.cutting->workpiece_material << ", "
        << c.cutting->workpiece_size << " |\n";
    out << "| cutting speed [m/min] | " << c.cutting->cutting_speed * 60.0 << " |\n";
    out << "| feed [mm/rev] | " << c.cutting->feed * mm << " |\n";
    out << "| depth of cut [mm] | " << c.cutting->depth_of_cut * mm << " |\n";
  }
  for (const Evaluation& e : evaluations) {
    out << "\n## Target " << e.target_name << "\n\n";
    out << "- model: " << fitting::model_label(e.model.spec) << ", sensors "
        << joined(e.model.features.sensor_names) << " (placement method " << chosen_method(e)
        << ")\n";
    out << "- `" << equation_text(e.model) << "`\n";
    out << "- fitted on: " << joined(e.model.fitted_on)
        << "; chosen on validation groups: " << joined(e.validation_groups) << "\n";
    out << "- gross errors rejected by 3σ: " << e.model.rejection.rejected << " of "
        << e.model.rejection.samples << " samples\n";
    out << "- test groups: " << joined(e.test_groups) << "\n\n";
    out << "| test group | S [µm] |\n| --- | --- |\n";
    for (std::size_t g = 0; g < e.test.s.size() && g < e.test_groups.size(); ++g)
      out << "| " << e.test_groups[g] << " | " << um_text(e.test.s[g]) << " |\n";
    if (!e.test.s.empty())
      out << "\nAccuracy S_M = " << um_text(e.test.sm)
          << " µm, robustness S_σ = " << um_text(e.test.s_sigma) << " µm.\n";
  }
  out << "\nCompensation: the CNC shifts the work origin by minus the predicted error. Refresh "
         "the model each quarter.\n";
  return out.str();
}

void write_modelling_record(const std::filesystem::path& json_path,
                            const std::filesystem::path& markdown_path,
                            const ModellingConditions& conditions,
                            const std::vector<Evaluation>& evaluations) {
  write_file_atomically(json_path, modelling_record_json(conditions, evaluations).dump(2) + "\n");
  write_file_atomically(markdown_path, modelling_record_markdown(conditions, evaluations));
}

std::string compensation_csv(const std::vector<FittedModel>& models,
                             const std::vector<fitting::Group>& groups) {
  std::ostringstream out;
  out.precision(10);
  out << "group,time_s,target,measured_um,predicted_um,compensation_um,"
         "residual_after_compensation_um\n";
  for (const fitting::Group& g : groups)
    for (const FittedModel& model : models) {
      if (model.target >= g.error.cols())
        throw core::DataError("group '" + g.name + "' has " + std::to_string(g.error.cols()) +
                              " targets; model '" + model.target_name + "' predicts target " +
                              std::to_string(model.target));
      const Eigen::VectorXd predicted = fitting::predicted_error(model, g);
      for (Eigen::Index i = 0; i < predicted.size(); ++i) {
        const double measured = g.error(i, model.target);
        const double compensation = -predicted(i);
        out << csv_field(g.name) << ',' << g.time(i) << ',' << csv_field(model.target_name) << ','
            << measured * um << ',' << predicted(i) * um << ',' << compensation * um << ','
            << (measured + compensation) * um << '\n';
      }
    }
  return out.str();
}

void write_compensation_csv(const std::filesystem::path& path,
                            const std::vector<FittedModel>& models,
                            const std::vector<fitting::Group>& groups) {
  write_file_atomically(path, compensation_csv(models, groups));
}

}  // namespace tt::io
