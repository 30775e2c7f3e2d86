#include "io/calibration_model_out.hpp"

#include <cctype>
#include <cmath>
#include <sstream>

#include "core/units.hpp"
#include "io/atomic_dir.hpp"
#include "io/calibration_effects_out.hpp"
#include "io/calibration_head.hpp"
#include "io/case_reader.hpp"
#include "io/model_out.hpp"
#include "io/plot.hpp"
#include "io/reports.hpp"

namespace tt::io {
namespace {

using nlohmann::json;

const char* const kDecisionRule =
    "an effect is claimed when its leave-one-run-out gain minus the complexity penalty "
    "(whitened sum "
    "of squares) beats both the best score of every candidate fitted to pure white noise at the "
    "estimated noise level and the model-form floor of the channels it moves; a candidate whose "
    "fitted parameters are unphysical (field `unphysical`) is never claimed; when the best "
    "candidate of another kind that would be claimed too scores less than the spread of the "
    "two candidates' per-run held-out gain differences (sqrt(#runs) x their standard "
    "deviation) below the best, neither is claimed and both are reported as `ambiguous`; the "
    "best "
    "pair of the first round's best candidates, scored jointly, replaces the claims made one "
    "after the other when it scores above them by more than that spread and each member adds "
    "more than the noise threshold and its floor to the other (`pairs`, `claimed_by`); the "
    "claims' sizes are then refitted about the updated model by Gauss-Newton (`refit`), and the "
    "refitted sizes kept only when, fitted on all training runs but one, they predict the one "
    "left out better than the linearised fit does (`refit.heldout_check`)";

/// A run name as a file name: letters and digits kept, anything else '_'.
std::string file_name(const std::string& run) {
  std::string s;
  for (char c : run) s += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return s.empty() ? "run" : s;
}

/// The model marched: {kind, nodes, order, build_s, indicator (reduced, backward Euler)}.
json marched_model_json(const studies::ModelUsed& m) {
  json j{{"kind", m.reduced ? "reduced" : "full"},
         {"nodes", m.nodes},
         {"order", m.order},
         {"build_s", m.build_s}};
  if (m.indicator) j["indicator"] = indicator_json(*m.indicator);
  return j;
}

CalibrationHead calibration_head(const studies::ModelCalibrationReport& report) {
  const calibration::CalibrationResult& res = report.result;
  CalibrationHead head;
  head.mode = "model (--case)";
  head.training_runs = report.training_runs;
  for (const auto& t : res.tests) head.test_runs.push_back(t.name);
  head.temperature_rms_K_before = res.before.temperature_rms_K;
  head.temperature_rms_K_after = res.after.temperature_rms_K;
  head.displacement_rms_um_before = res.before.displacement_rms_m * core::kMicrometresPerMetre;
  head.displacement_rms_um_after = res.after.displacement_rms_m * core::kMicrometresPerMetre;
  head.channels = report.channels;
  return head;
}

/// augmented/<run>.toml per test run and augmented_case.toml (the first); returns
/// calibration.json's `augmented_cases` and `sensor_corrections` (also sensor_corrections.json).
std::pair<json, json> write_augmented_cases(const std::filesystem::path& dir,
                                            const calibration::CalibrationResult& res) {
  std::filesystem::create_directories(dir / "augmented");
  json corrections = json::array(), files = json::array();
  for (std::size_t k = 0; k < res.tests.size(); ++k) {
    const auto& t = res.tests[k];
    const std::string toml = resolved_case_toml(t.augmented.spec);
    const auto name = "augmented/" + file_name(t.name) + ".toml";
    write_file_atomically(dir / name, toml);
    if (k == 0) write_file_atomically(dir / "augmented_case.toml", toml);
    files.push_back({{"run", t.name}, {"case", name}});
    for (const auto& c : t.augmented.sensors)
      corrections.push_back(
          {{"run", t.name}, {"sensor", c.sensor}, {"offset_K", c.offset_K}, {"lag_s", c.lag_s}});
  }
  write_json(dir / "sensor_corrections.json", corrections);
  return {files, corrections};
}

/// residuals.csv (before, after and the effect, before - after, per sample) and its figures.
void write_residuals(const std::filesystem::path& dir,
                     const studies::ModelCalibrationReport& report) {
  std::ostringstream csv;
  csv << "run,channel,unit,time_s,before,after,effect\n";
  for (const auto& t : report.result.tests)
    for (std::size_t c = 0; c < report.channels.size(); ++c) {
      const bool temp = report.channels[c].temperature;
      const double s = temp ? 1.0 : 1e6;
      const auto col = static_cast<Eigen::Index>(c);
      for (Eigen::Index i = 0; i < t.times.size(); ++i) {
        const double m = t.measured(i, col);
        if (!std::isfinite(m)) continue;
        csv << '"' << t.name << "\"," << report.channels[c].id << ',' << (temp ? "K" : "um") << ','
            << t.times(i) << ',' << s * (m - t.before(i, col)) << ',' << s * (m - t.after(i, col))
            << ',' << s * (t.after(i, col) - t.before(i, col)) << '\n';
      }
    }
  write_file_atomically(dir / "residuals.csv", csv.str());
  plot({"residuals", (dir / "residuals.csv").string(), (dir / "residual_before_after.png").string(),
        "--effect-out=" + (dir / "effect.png").string()});
}

void ambiguous_markdown(std::ostream& md, const json& ambiguous) {
  if (ambiguous.empty()) return;
  md << "## Ambiguous\n\n";
  for (const auto& a : ambiguous) {
    const auto& c = a["candidates"];
    md << "The data do not tell **" << c[0]["name"].get<std::string>() << "** ("
       << c[0]["kind"].get<std::string>() << ", score " << c[0]["score"].get<double>()
       << ") from **" << c[1]["name"].get<std::string>() << "** ("
       << c[1]["kind"].get<std::string>() << ", score " << c[1]["score"].get<double>()
       << "): their scores differ by " << a["score_difference"].get<double>()
       << ", less than the spread of their per-run held-out gains (" << a["spread"].get<double>()
       << "), so neither is claimed. Their fitted predictions "
       << "differ most on `" << a["distinguishing_channel"]["channel"].get<std::string>() << "` ("
       << a["distinguishing_channel"]["rms_difference_sigmas"].get<double>()
       << " noise sigmas RMS). To tell them apart: " << a["hint"].get<std::string>() << ".\n\n";
  }
}

void refits_markdown(std::ostream& md, const json& effects) {
  for (const auto& e : effects)
    if (e.contains("refit") && e["refit"].contains("linearised"))
      md << "- " << e["name"].get<std::string>() << ": refitted about the updated model in "
         << e["refit"]["iterations"].get<int>() << " Gauss–Newton step(s)"
         << (e["refit"]["converged"].get<bool>() ? "" : " (iteration cap reached)")
         << ": linearised `" << e["refit"]["linearised"].dump() << "`, refitted `"
         << e["refit"]["refitted"].dump() << "`"
         << (e["refit"].value("kept", true)
                 ? ""
                 : " (not kept: on the runs left out of the fit it predicted worse than the "
                   "claim as chosen, which is written)")
         << "\n";
}

/// `sel`: calibration.json's account of the choice (selection_json).
void effects_markdown(std::ostream& md, const json& sel, double null_score) {
  if (sel["effects"].empty()) {
    if (sel["ambiguous"].empty())
      md << "No effect claimed: no physical candidate's held-out gain beat both the noise "
            "threshold ("
         << null_score << ") and its model-form floor.\n\n";
  } else {
    md << "## Claimed effects\n\n";
    for (const auto& e : sel["effects"])
      md << "- **" << e["kind"].get<std::string>() << "**: " << e["name"].get<std::string>()
         << "; explained fraction " << e["explained_fraction"].get<double>() << "; score "
         << e["score"].get<double>() << " (noise threshold " << null_score << ", floor "
         << e["model_form_floor"].get<double>() << ")\n  - parameters: `" << e["parameters"].dump()
         << "`\n  - location: `" << e["location"].dump() << "`\n";
    refits_markdown(md, sel["effects"]);
  }
  for (const auto& e : sel["refit_rejected"])
    md << "- not claimed: " << e["name"].get<std::string>() << ", whose size refitted about "
       << "the updated model is unphysical (" << e.value("unphysical", "") << ")\n";
  md << "\n## Runners-up\n\nA candidate marked unphysical needs a value outside its bounds "
        "(docs/calibration.md) to fit and is never claimed, however well it scores.\n\n"
        "| kind | name | explained fraction | score | unphysical |\n| --- | --- | --- | --- | --- "
        "|\n";
  for (const auto& e : sel["runners_up"])
    md << "| " << e["kind"].get<std::string>() << " | " << e["name"].get<std::string>() << " | "
       << e["explained_fraction"].get<double>() << " | " << e["score"].get<double>() << " | "
       << e.value("unphysical", "") << " |\n";
}

std::string report_markdown(const studies::ModelCalibrationReport& report) {
  const calibration::CalibrationResult& res = report.result;
  const studies::ModelUsed& m = report.model;
  std::ostringstream md;
  md << "# Calibration of " << report.case_name << "\n\n";
  md << "Training runs: ";
  for (const auto& n : report.training_runs) md << "`" << n << "` ";
  md << "\n\nTest runs: ";
  for (const auto& t : res.tests) md << "`" << t.name << "` ";
  md << "\n\nModel marched: "
     << (m.reduced ? "reduced, order " + std::to_string(m.order) + " of " +
                         std::to_string(m.nodes) + " nodes"
                   : "full order, " + std::to_string(m.nodes) + " nodes")
     << " (`model` in calibration.json).";
  md << "\n\n| | temperature RMS [K] | displacement RMS [um] |\n| --- | --- | --- |\n";
  md << "| before | " << res.before.temperature_rms_K << " | "
     << res.before.displacement_rms_m * core::kMicrometresPerMetre << " |\n";
  md << "| after | " << res.after.temperature_rms_K << " | "
     << res.after.displacement_rms_m * core::kMicrometresPerMetre << " |\n\n";
  const json sel = selection_json(res);
  ambiguous_markdown(md, sel["ambiguous"]);
  effects_markdown(md, sel, res.selection.null_score);
  md << "\n## Figures\n\n![residual before and after](residual_before_after.png)\n\n![identified "
        "effect](effect.png)\n\n";
  md << "The augmented case for each test run is in `augmented/`; `augmented_case.toml` is the "
        "first. Sensor offsets "
        "and lags, which a case file cannot declare, are in `sensor_corrections.json` and are "
        "applied to the "
        "simulated readings. See docs/calibration.md.\n";
  return md.str();
}

}  // namespace

json selection_json(const calibration::CalibrationResult& res) {
  json sigma = json::array();
  for (Eigen::Index c = 0; c < res.selection.sigma.size(); ++c)
    sigma.push_back(res.selection.sigma(c));
  const calibration::Naming& names = res.naming;
  json effects = json::array(), runners_up = json::array(), ambiguous = json::array(),
       refit_rejected = json::array(), pairs = json::array();
  for (const auto& e : res.effects) effects.push_back(effect_json(e, names));
  for (const auto& e : res.runners_up) runners_up.push_back(effect_json(e, names));
  for (const auto& a : res.ambiguous) ambiguous.push_back(ambiguity_json(a, names));
  for (const auto& e : res.refit_rejected) refit_rejected.push_back(effect_json(e, names));
  for (const auto& p : res.pairs) pairs.push_back(pair_json(p, names));
  return {{"effects", effects},
          {"runners_up", runners_up},
          {"ambiguous", ambiguous},
          {"refit_rejected", refit_rejected},
          {"pairs", pairs},
          {"claimed_by",
           res.selection.by_pair ? "the best pair scored jointly" : "one effect after the other"},
          {"decision",
           {{"rule", kDecisionRule},
            {"null_score", res.selection.null_score},
            {"training_residual_whitened_ss", res.selection.residual_ss},
            {"noise_sigma_per_channel", sigma}}}};
}

void write_model_calibration(const std::filesystem::path& dir,
                             const studies::ModelCalibrationReport& report) {
  const auto [augmented_cases, corrections] = write_augmented_cases(dir, report.result);
  json doc = calibration_head_json(calibration_head(report));
  doc.update(selection_json(report.result));
  doc["augmented_cases"] = augmented_cases;
  doc["sensor_corrections"] = corrections;
  doc["runtime_s"] = report.runtime_s;
  doc["model"] = marched_model_json(report.model);
  write_json(dir / "calibration.json", doc);
  write_residuals(dir, report);
  write_file_atomically(dir / "report.md", report_markdown(report));
}

}  // namespace tt::io
