#include "io/calibration_data_out.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "io/atomic_dir.hpp"
#include "io/calibration_head.hpp"
#include "io/csv_out.hpp"
#include "io/plot.hpp"
#include "io/reports.hpp"

namespace tt::io {
namespace {

using nlohmann::json;
constexpr double um = 1e6;  // metres to micrometres

json effect_json(const fitting::Effect& e, const studies::ChannelCalibration& ch,
                 const std::vector<std::string>& sensor_names) {
  const fitting::TermModel& with = ch.study.after;
  json parameters = json::object();
  if (e.term.kind == fitting::TermKind::lag || e.term.kind == fitting::TermKind::lagged_speed)
    parameters["time_constant_s"] = e.term.time_constant;
  if (e.term.sensor >= 0)
    parameters["sensor"] = sensor_names[static_cast<std::size_t>(e.term.sensor)];
  // The coefficients this term has in the final model, by regressor name [µm per unit].
  const auto names = fitting::term_regressor_names(with.baseline, with.terms, sensor_names);
  const auto before = fitting::term_regressor_names(with.baseline, {}, sensor_names).size();
  std::size_t at = before;
  for (const auto& t : with.terms) {
    const auto count =
        fitting::term_regressor_names(with.baseline, {t}, sensor_names).size() - before;
    if (t.kind == e.term.kind)
      for (std::size_t k = 0; k < count; ++k)
        parameters["coefficients_um"][names[at + k]] =
            with.fit.coefficients(static_cast<Eigen::Index>(at + k)) * um;
    at += count;
  }
  json location{{"channel", ch.name}};
  if (e.term.sensor >= 0)
    location["sensor"] = sensor_names[static_cast<std::size_t>(e.term.sensor)];
  return {{"kind", fitting::term_kind_name(e.term.kind)},
          {"parameters", parameters},
          {"location", location},
          {"explained_fraction", e.explained_fraction},
          {"step_fraction", e.step_fraction},
          {"null_fraction", finite_or_null(e.null_fraction)},
          {"added_coefficients", e.parameters},
          {"heldout_training_rms_um_before", finite_or_null(e.heldout_rms_before, um)},
          {"heldout_training_rms_um_with_it", finite_or_null(e.heldout_rms_after, um)},
          {"heldout_gain_t",
           std::isfinite(e.gain_t) ? json(e.gain_t) : json(e.gain_t > 0 ? 1e300 : 0.0)},
          {"segments_improved", e.segments_improved},
          {"claimed", e.claimed}};
}

json model_json(const fitting::TermModel& m, const std::vector<std::string>& sensor_names) {
  json terms = json::object();
  const auto names = fitting::term_regressor_names(m.baseline, m.terms, sensor_names);
  for (std::size_t k = 0; k < names.size(); ++k)
    terms[names[k]] = m.fit.coefficients(static_cast<Eigen::Index>(k)) * um;
  return {{"form", fitting::model_label(m.baseline.spec)},
          {"intercept_um", m.fit.intercept * um},
          {"coefficients_um_per_unit", terms},
          {"units", "dT in K, d[speed_rpm] in rpm, speed_krpm in krpm, time in h"}};
}

json baseline_choice_json(const fitting::Evaluation& choice) {
  const auto& chosen = choice.selection.candidates[static_cast<std::size_t>(choice.selection.best)];
  return {{"model", fitting::model_label(choice.model.spec)},
          {"validation_rms_um", std::sqrt(fitting::mean_square(chosen.validation)) * um},
          {"gain_over_no_compensation_um2", finite_or_null(choice.selection.gain_over_none, 1e12)},
          {"gain_over_no_compensation_standard_error_um2",
           finite_or_null(choice.selection.gain_over_none_standard_error, 1e12)}};
}

json correlations_json(const studies::ResidualCorrelations& c, bool has_speed,
                       const std::vector<std::string>& sensor_names) {
  json d{{"time_since_segment_start", c.time_since_segment_start}};
  // A run with no speed input has no speed to correlate with: no column of zeros.
  if (has_speed) d["speed"] = c.speed;
  for (Eigen::Index k = 0; k < c.temperature_rises.size(); ++k)
    d["dT[" + sensor_names[static_cast<std::size_t>(k)] + "]"] = c.temperature_rises(k);
  return d;
}

json runs_json(const SplitRuns& runs) {
  json splits = json::array();
  for (const auto& r : runs.runs) {
    json segments = json::array();
    for (const auto& s : r.segments)
      segments.push_back({{"name", s.name},
                          {"from_s", s.from_s},
                          {"to_s", s.to_s},
                          {"dropped_rows", s.dropped_rows}});
    splits.push_back({{"folder", r.folder.string()},
                      {"role", r.train ? "train" : "test"},
                      {"split_s", r.split_s ? json(*r.split_s) : json(nullptr)},
                      {"segments", segments}});
  }
  return splits;
}

const char* const kBaselineMethod =
    "the model fit --data chooses on the same training blocks (same candidates, same rule): no "
    "compensation, least squares, ridge, or ridge on every temperature rise with its first-order "
    "lags at 600 s and 3600 s (and the speed with its lags, where there is one), lambda in "
    "1e-6..10, the lowest mean held-out S^2 guarded by one standard error against no "
    "compensation; effects are fitted jointly with it under its lambda";
const char* const kThreshold =
    "claimed when step_fraction - 0.01 x added_coefficients > null_fraction, the largest share "
    "reached by 19 phase-randomised surrogates of the same term (same amplitude spectrum, random "
    "phases, one surrogate per segment), each searched over the same settings, and never below 0 "
    "(a term with no relation to the residual beats all 19 with probability 1/20), and when its "
    "per-segment held-out gain is more than 2 standard errors above 0 (heldout_gain_t > 2: the "
    "gain holds from segment to segment)";
const char* const kNoTemperature =
    "not applicable: no machine model behind the data, so no temperature is predicted (reported "
    "as null)";

/// calibration.json's head (io/calibration_head.hpp): no machine model, so no temperature figure.
CalibrationHead calibration_head(const studies::DataCalibrationReport& r, const SplitRuns& runs) {
  CalibrationHead head;
  head.mode = "data-driven (no --case)";
  for (const auto& run : runs.runs)
    (run.train ? head.training_runs : head.test_runs).push_back(run.folder.string());
  head.temperature_note = kNoTemperature;
  head.displacement_rms_um_before = r.rms_before * um;
  head.displacement_rms_um_after = r.rms_after * um;
  for (const auto& ch : r.channels)
    head.channels.push_back({ch.name, false, ch.figures_before, ch.figures_after});
  return head;
}

json calibration_document(const studies::DataCalibrationReport& r, const SplitRuns& runs) {
  json tested = json::object(), models = json::object(), diagnosis = json::object(),
       effects = json::array();
  for (const auto& ch : r.channels) {
    for (std::size_t k = 0; k < ch.study.effects.size(); ++k) {
      json e = effect_json(ch.study.effects[k], ch, r.sensor_names);
      e["test_rms_um_with_effects_so_far"] = ch.test_rms_with_effects_so_far[k] * um;
      e["test_rms_um_before"] = ch.figures_before.rms * um;
      effects.push_back(e);
    }
    tested[ch.name] = json::array();
    for (const auto& step : ch.study.steps) {
      tested[ch.name].push_back(json::array());
      for (const auto& e : step)
        tested[ch.name].back().push_back(effect_json(e, ch, r.sensor_names));
    }
    models[ch.name] = {{"baseline_choice", baseline_choice_json(ch.choice)},
                       {"before", model_json(ch.study.before, r.sensor_names)},
                       {"after", model_json(ch.study.after, r.sensor_names)},
                       {"heldout_training_rss_um2_before", ch.study.heldout_rss_before * 1e12},
                       {"heldout_training_rss_um2_after", ch.study.heldout_rss_after * 1e12}};
    diagnosis[ch.name] = {
        {"before", correlations_json(ch.correlations_before, r.has_speed, r.sensor_names)},
        {"after", correlations_json(ch.correlations_after, r.has_speed, r.sensor_names)}};
  }
  std::stable_sort(effects.begin(), effects.end(), [](const json& a, const json& b) {
    return a["explained_fraction"].get<double>() > b["explained_fraction"].get<double>();
  });
  json doc = calibration_head_json(calibration_head(r, runs));
  doc["runs"] = runs_json(runs);
  doc["effects"] = effects;
  doc["tested_per_step"] = tested;
  doc["models"] = models;
  doc["test_residual_correlations"] = diagnosis;
  doc["method"] = {
      {"baseline", kBaselineMethod},
      {"explained_fraction",
       "share of the baseline's leave-one-segment-out training residual sum of squares the "
       "effect removes (given the effects added before it)"},
      {"threshold", kThreshold},
      {"segments", r.block_origin + "; each segment's drift re-zeroed at its start"}};
  doc["speed_input"] = r.has_speed;
  return doc;
}

std::string report_markdown(const studies::DataCalibrationReport& r, const json& doc) {
  std::ostringstream md;
  md.setf(std::ios::fixed);
  md.precision(2);
  md << "# calibrate (data-driven)\n\nTraining segments: " << r.training.size() << " ("
     << r.block_origin << "), test segments: " << r.test_segments
     << (r.has_speed ? "" : ". The runs have no speed input: no speed term is tried")
     << ". No machine model: temperatures are inputs, not predictions, so `temperature_rms_K` is "
        "null.\n\n"
     << "Before: per channel, the model `fit --data` chooses on the same training blocks (blocked "
        "cross-validation); after: with the claimed effects added.\n\n"
     << "| channel | before: chosen model | test RMS before [um] | test RMS after [um] | test MAE "
        "before [um] | test MAE after [um] |\n"
     << "|---|---|---|---|---|---|\n";
  for (const auto& ch : r.channels)
    md << "| " << ch.name << " | `" << fitting::model_label(ch.choice.model.spec) << "` | "
       << ch.figures_before.rms * um << " | " << ch.figures_after.rms * um << " | "
       << ch.figures_before.mae * um << " | " << ch.figures_after.mae * um << " |\n";
  md << "| all | | " << r.rms_before * um << " | " << r.rms_after * um << " | | |\n\n";
  const json& worse = doc["after_worse_than_before_on_test"];
  if (!worse.empty()) {
    md << "**Worse after than before on the test data:**";
    for (const auto& ch : r.channels)
      if (ch.worse_after_than_before())
        md << " " << ch.name << " (" << ch.figures_before.rms * um << " -> "
           << ch.figures_after.rms * um << " um RMS)";
    md << ". The effects were claimed on held-out training segments only; on these test data "
          "they do not hold.\n\n";
  }
  md << "## Effects claimed\n\n";
  const json& effects = doc["effects"];
  if (effects.empty()) {
    md << "None: no candidate term beat its surrogates with a gain that holds from segment to "
          "segment.\n";
  } else {
    md << "| kind | channel | parameters | explained fraction | null threshold | held-out "
          "training RMS before -> with it [um] | gain t | test RMS with it [um] |\n"
       << "|---|---|---|---|---|---|---|---|\n";
    md.precision(3);
    for (const auto& e : effects)
      md << "| " << e["kind"].get<std::string>() << " | "
         << e["location"]["channel"].get<std::string>() << " | `" << e["parameters"].dump()
         << "` | " << e["explained_fraction"].get<double>() << " | "
         << e["null_fraction"].get<double>() << " | "
         << e["heldout_training_rms_um_before"].get<double>() << " -> "
         << e["heldout_training_rms_um_with_it"].get<double>() << " | "
         << e["heldout_gain_t"].get<double>() << " | "
         << e["test_rms_um_with_effects_so_far"].get<double>() << " |\n";
  }
  md << "\nHow an effect is claimed: " << kThreshold << ".\n\n## Test residual\n\n";
  for (const auto& ch : r.channels) md << "![" << ch.name << "](residual_" << ch.name << ".png)\n";
  return md.str();
}

/// residual_<channel>.csv and its figure: the test segments end to end, in µm (speed in krpm).
void write_residual(const std::filesystem::path& dir, const studies::ChannelCalibration& ch,
                    bool has_speed) {
  const Eigen::MatrixXd& t = ch.test_table;
  const auto csv = dir / ("residual_" + ch.name + ".csv");
  const auto png = (dir / ("residual_" + ch.name + ".png")).string();
  if (has_speed) {
    Eigen::MatrixXd table(t.rows(), 6);
    table << t.col(0), t.col(1) / 1000.0, t.col(2) * um, t.col(3) * um, ch.before * um,
        ch.after * um;
    write_csv(csv,
              {"time_s", "speed_krpm", "measured_um", "predicted_before_um", "residual_before_um",
               "residual_after_um"},
              table);
    plot({"lines", csv.string(), png, "--x", "time_s", "--columns",
          "speed_krpm,measured_um,residual_before_um,residual_after_um", "--ylabel",
          "um (speed: krpm)", "--title=test segments, channel " + ch.name});
  } else {
    Eigen::MatrixXd table(t.rows(), 5);
    table << t.col(0), t.col(2) * um, t.col(3) * um, ch.before * um, ch.after * um;
    write_csv(
        csv,
        {"time_s", "measured_um", "predicted_before_um", "residual_before_um", "residual_after_um"},
        table);
    plot({"lines", csv.string(), png, "--x", "time_s", "--columns",
          "measured_um,residual_before_um,residual_after_um", "--ylabel", "um",
          "--title=test segments, channel " + ch.name});
  }
}

}  // namespace

void write_data_calibration(const std::filesystem::path& dir,
                            const studies::DataCalibrationReport& report, const SplitRuns& runs) {
  const json doc = calibration_document(report, runs);
  write_json(dir / "calibration.json", doc);
  for (const auto& ch : report.channels) write_residual(dir, ch, report.has_speed);
  write_file_atomically(dir / "report.md", report_markdown(report, doc));
}

}  // namespace tt::io
