#include "io/fit_data_out.hpp"

#include <cmath>
#include <sstream>

#include "io/atomic_dir.hpp"
#include "io/csv_out.hpp"
#include "io/fitting_out.hpp"
#include "io/network_out.hpp"
#include "io/plot.hpp"
#include "io/reports.hpp"

namespace tt::io {
namespace {

using nlohmann::json;

std::string um(double metres, int digits = 2) {
  if (!std::isfinite(metres)) return "-";
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << metres * 1e6;
  return s.str();
}

const fitting::CandidateResult& candidate(const fitting::Evaluation& e, int index) {
  return e.selection.candidates[static_cast<std::size_t>(index)];
}

const std::string& method_of(const fitting::Evaluation& e, const fitting::CandidateResult& c) {
  return e.sensor_sets[static_cast<std::size_t>(c.sensor_set)].method;
}

/// The blocked choice's validation figures: the chosen candidate beside the lowest one and no
/// compensation [um, um²].
json validation_json(const fitting::Evaluation& e, std::size_t blocks) {
  const auto& chosen = candidate(e, e.selection.best);
  const auto& lowest = candidate(e, e.selection.lowest);
  const auto rms = [](const fitting::CandidateResult& c) {
    return std::sqrt(fitting::mean_square(c.validation)) * 1e6;
  };
  return {{"validation_sm_um", chosen.validation.sm * 1e6},
          {"validation_standard_error_um",
           chosen.validation.s_sigma / std::sqrt(static_cast<double>(blocks)) * 1e6},
          {"lowest_validation_candidate",
           fitting::model_label(e.specs[static_cast<std::size_t>(lowest.spec)]) + " on " +
               method_of(e, lowest)},
          {"lowest_validation_sm_um", lowest.validation.sm * 1e6},
          {"validation_rms_um", rms(chosen)},
          {"lowest_validation_rms_um", rms(lowest)},
          {"no_compensation_validation_rms_um",
           e.selection.none >= 0 ? json(rms(candidate(e, e.selection.none))) : json(nullptr)},
          {"gain_over_no_compensation_um2", finite_or_null(e.selection.gain_over_none * 1e12)},
          {"gain_over_no_compensation_standard_error_um2",
           finite_or_null(e.selection.gain_over_none_standard_error * 1e12)}};
}

/// fit.json's summary of one channel: the choice, its validation and test figures [um].
json channel_summary(const studies::DataFitChannel& ch, std::size_t blocks,
                     const std::optional<PublishedFigure>& published) {
  const auto& e = ch.evaluation;
  json s{{"model", fitting::model_label(e.model.spec)},
         {"method", method_of(e, candidate(e, e.selection.best))},
         {"sensors", e.model.features.sensor_names},
         {"inputs", e.model.features.input_names}};
  s.update(validation_json(e, blocks));
  json test_s = json::array();
  for (double v : e.test.s) test_s.push_back(v * 1e6);
  s.update(json{{"test_s_um", test_s},
                {"test_sm_um", e.test.sm * 1e6},
                {"test_s_sigma_um", finite_or_null(e.test.s_sigma, 1e6)},
                {"test_rms_um", ch.test.rms * 1e6},
                {"test_max_abs_um", ch.test.max_abs * 1e6},
                {"test_rms_uncompensated_um", ch.uncompensated.rms * 1e6},
                {"test_max_abs_uncompensated_um", ch.uncompensated.max_abs * 1e6},
                {"worse_than_uncompensated_on_test", ch.test.rms > ch.uncompensated.rms},
                {"window_mae_rezeroed_um", ch.test.mae * 1e6},
                {"window_mae_uncompensated_um", ch.uncompensated.mae * 1e6},
                {"window_mae_continuous_um", nullptr}});
  if (published && published->mae_um.count(e.target_name))
    s["published_mae_um"] = published->mae_um.at(e.target_name);
  if (ch.window)
    s["window_mae_continuous_um"] =
        core::error_figures(ch.window->measured - ch.window->predicted).mae * 1e6;
  if (ch.network) {
    json& n = s["network"] = network_json(ch.network->figures);
    n["window_mae_rezeroed_um"] = ch.network->test.mae * 1e6;
    if (ch.network->window_mae_continuous)
      n["window_mae_continuous_um"] = *ch.network->window_mae_continuous * 1e6;
    n["file"] = "network_" + e.target_name + ".pt";
  }
  return s;
}

json runs_json(const DataFitRuns& runs) {
  json out = json::array();
  for (const auto& r : runs.runs)
    out.push_back({{"folder", r.folder.string()},
                   {"machine", r.machine},
                   {"run", r.run},
                   {"role", r.training ? "training" : "test"},
                   {"speed_input", runs.has_speed}});
  return out;
}

json groups_json(const studies::DataFitReport& r) {
  json out = json::array();
  for (std::size_t i = 0; i < r.segments.size(); ++i) {
    const auto& g = r.segments[i].group;
    out.push_back({{"name", g.name},
                   {"role", i >= r.blocks ? "test" : "fitting_and_validation"},
                   {"from_s", g.time(0)},
                   {"to_s", g.time(g.time.size() - 1)},
                   {"samples", g.time.size()},
                   {"dropped_rows", r.segments[i].dropped_rows}});
  }
  return out;
}

json out_of_range_json(const std::vector<fitting::OutOfRange>& out_of_range) {
  json out = json::array();
  for (const auto& o : out_of_range)
    out.push_back({{"column", o.column},
                   {"training_min", o.training_min},
                   {"training_max", o.training_max},
                   {"test_min", o.test_min},
                   {"test_max", o.test_max},
                   {"share_of_test_samples_outside", o.share_outside},
                   {"units", "K for dT, rpm for d[speed_rpm]"}});
  return out;
}

constexpr const char* kSelectionRule =
    "blocked cross-validation (each training block held out in turn): the candidate of "
    "the lowest mean validation S^2 (validation_rms_um is its square root; ties to the "
    "fewer coefficients), unless its mean per-block gain in S^2 over no compensation does "
    "not exceed one standard error of that gain: then no compensation (one-standard-error "
    "guard), so a model worse than no compensation on validation is never chosen";

json method_notes(const std::string& block_origin) {
  return {"training blocks: " + block_origin +
              "; each block's drift is re-zeroed at its first reading, as the standard's "
              "intercept assumes",
          "candidates: no compensation; least squares (with the standard's 3 sigma criterion, "
          "and without it), ridge and ridge on the temperatures with their first-order lags at "
          "600 s and 3600 s (and the speed with its lags, where there is one) on all sensors, "
          "ridge strength lambda in 1e-6..10",
          "test_rms_um and test_max_abs_um: residual on the held-out groups, re-zeroed at each "
          "group's start; window_mae_continuous_um (a window inside a run only): the chosen form "
          "refitted on the whole run outside the window, temperatures from the run's start, no "
          "displacement inside the window used"};
}

json fit_document(const studies::DataFitReport& r, const DataFitRuns& runs) {
  std::vector<fitting::Evaluation> evals;
  for (const auto& ch : r.channels) evals.push_back(ch.evaluation);
  json doc = fit_json(evals);
  for (auto& t : doc["targets"]) t["selection_rule"] = kSelectionRule;
  doc["summary"] = json::object();
  for (const auto& ch : r.channels)
    doc["summary"][ch.evaluation.target_name] = channel_summary(ch, r.blocks, runs.published);
  doc["data"] = runs_json(runs);
  doc["blocks"] = r.block_origin;
  doc["groups"] = groups_json(r);
  doc["test_window"] = {{"from_s", finite_or_null(runs.from_s)},
                        {"to_s", finite_or_null(runs.to_s)},
                        {"origin", runs.window_origin}};
  doc["out_of_training_range"] = out_of_range_json(r.out_of_range);
  doc["method_notes"] = method_notes(r.block_origin);
  if (const auto& p = runs.published)
    doc["published"] = {{"model", p->model},
                        {"source", p->source},
                        {"note", p->note},
                        {"mae_um", p->mae_um},
                        {"others_mae_um", p->others_mae_um}};
  return doc;
}

/// One row of summary.md's table, from the channel's summary in fit.json.
std::string channel_row(const fitting::Evaluation& e, const json& s) {
  std::string sensors;
  for (const auto& n : e.model.features.sensor_names) sensors += (sensors.empty() ? "" : " ") + n;
  for (const auto& n : e.model.features.input_names) sensors += " " + n;
  const auto field = [&](const char* key) {
    return s[key].is_number() ? um(s[key].get<double>() * 1e-6) : std::string("-");
  };
  std::ostringstream md;
  md << "| " << e.target_name << " | " << fitting::model_label(e.model.spec) << " | "
     << (e.model.spec.kind == fitting::ModelKind::no_compensation ? "-" : sensors) << " | "
     << field("test_rms_um") << " | " << field("test_max_abs_um") << " | "
     << field("test_rms_uncompensated_um") << " | " << field("test_max_abs_uncompensated_um")
     << " | " << um(e.test.sm) << " | " << field("window_mae_continuous_um") << " | "
     << (s.contains("published_mae_um") ? um(s["published_mae_um"].get<double>() * 1e-6, 3) : "-")
     << " |\n";
  return md.str();
}

std::string summary_markdown(const studies::DataFitReport& r, const DataFitRuns& runs,
                             const json& doc) {
  std::ostringstream md;
  md << "# fit --data\n\nRuns: ";
  for (const auto& run : runs.runs)
    md << "`" << run.folder.string() << "` (" << run.run << (run.training ? "" : ", test") << ") ";
  md << "\n\nHeld out: " << runs.window_origin;
  if (std::isfinite(runs.from_s) || std::isfinite(runs.to_s))
    md << ", " << (std::isfinite(runs.from_s) ? std::to_string(runs.from_s) : "start") << " to "
       << (std::isfinite(runs.to_s) ? std::to_string(runs.to_s) : "end") << " s";
  md << ". Training blocks: " << r.block_origin << ". Test groups: " << r.segments.size() - r.blocks
     << ".\n\n"
     << "| channel | model | sensors | test RMS [um] | test max [um] | uncompensated RMS [um] | "
        "uncompensated max [um] | test S_M [um] | MAE continuous [um] | published MAE [um] "
        "|\n|---|---|---|---|---|---|---|---|---|---|\n";
  std::string worse;
  for (const auto& ch : r.channels) {
    const json& s = doc["summary"][ch.evaluation.target_name];
    md << channel_row(ch.evaluation, s);
    if (s["worse_than_uncompensated_on_test"].get<bool>()) worse += " " + ch.evaluation.target_name;
  }
  if (!worse.empty())
    md << "\n**Worse than no compensation on the test data:**" << worse
       << ". The choice was made on the training blocks only; this says the test data differ "
          "from them.\n";
  if (!r.out_of_range.empty()) {
    md << "\n**Test inputs outside the training range** (the models extrapolate there):";
    for (const auto& o : r.out_of_range)
      md << " " << o.column << " (" << std::lround(o.share_outside * 100.0)
         << " % of test samples)";
    md << ".\n";
  }
  if (const auto& p = runs.published)
    md << "\nPublished: " << p->model << ", " << p->source << ". " << p->note << ".\n";
  md << "\nChoice: " << kSelectionRule
     << ". S, S_M, S_sigma: DB3401/T 326-2024 formulas 5-7 over the test groups. See fit.json "
        "`method_notes`.\n";
  return md.str();
}

/// The window's measured and continuously predicted drift [um], as CSV and as a figure.
void write_window(const std::filesystem::path& dir, const std::string& channel,
                  const studies::WindowPrediction& w) {
  Eigen::MatrixXd rows(w.time.size(), 3);
  rows << w.time, w.measured * 1e6, w.predicted * 1e6;
  const auto csv = dir / ("window_" + channel + ".csv");
  write_csv(csv, {"time_s", "measured_um", "predicted_continuous_um"}, rows);
  plot({"lines", csv.string(), (dir / ("window_" + channel + ".png")).string(), "--x", "time_s",
        "--columns", "measured_um,predicted_continuous_um", "--ylabel=" + channel + " [um]",
        "--title=test window, channel " + channel});
}

}  // namespace

std::string data_fit_progress(const studies::DataFitReport& r) {
  std::ostringstream line;
  if (r.channels.empty()) {
    line << r.blocks << " training blocks (" << r.block_origin << "), "
         << r.segments.size() - r.blocks << " test groups, " << r.channel_count << " channels";
    return line.str();
  }
  const auto& ch = r.channels.back();
  const auto& e = ch.evaluation;
  line << e.target_name << ": " << fitting::model_label(e.model.spec) << " on "
       << method_of(e, candidate(e, e.selection.best)) << ", test RMS " << um(ch.test.rms)
       << " um (uncompensated " << um(ch.uncompensated.rms) << ")";
  return line.str();
}

void write_data_fit(const std::filesystem::path& dir, const studies::DataFitReport& report,
                    const DataFitRuns& runs) {
  const json doc = fit_document(report, runs);
  write_json(dir / "fit.json", doc);
  std::vector<fitting::FittedModel> models;
  for (const auto& ch : report.channels) {
    models.push_back(ch.evaluation.model);
    if (ch.network)
      write_network(dir / ("network_" + ch.evaluation.target_name + ".pt"),
                    ch.network->figures.model);
  }
  write_compensation_csv(dir / "compensation.csv", models, report.test_groups());
  write_file_atomically(dir / "summary.md", summary_markdown(report, runs, doc));
  for (const auto& ch : report.channels)
    if (ch.window) write_window(dir, ch.evaluation.target_name, *ch.window);
}

}  // namespace tt::io
