// thermotwin calibrate --case CASE --train RUN... --test RUN... --out DIR: the model-based side of
// closing the loop. Simulates the declared case under each measured run's speed column, forms
// the residual of every channel, finds the undeclared effect that explains it (held-out training
// runs, noise threshold), writes the augmented case and evaluates it on the test runs.
// Writes DIR/calibration.json, DIR/report.md, DIR/augmented_case.toml (the first test run's
// inputs), DIR/augmented/<run>.toml per test run, DIR/sensor_corrections.json, DIR/residuals.csv
// and the figures residual_before_after.png and effect.png.
#include <cctype>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>

#include "app/commands.hpp"
#include "app/study.hpp"
#include "calibration/calibrate.hpp"
#include "core/errors.hpp"
#include "core/timing.hpp"
#include "io/atomic_dir.hpp"
#include "io/case_reader.hpp"
#include "io/csv_out.hpp"
#include "io/measured_data.hpp"
#include "io/reports.hpp"
#include "mesh/mesher.hpp"
#include "solvers/twin.hpp"

namespace tt::app {

using core::seconds_since;
namespace {

using Clock = std::chrono::steady_clock;

std::string file_name(const std::string& run) {
  std::string s;
  for (char c : run) s += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return s.empty() ? "run" : s;
}

void write_text(const std::filesystem::path& p, const std::string& s) {
  io::write_file_atomically(p, s);
}

}  // namespace

int calibrate_command_with_case(const CalibrateArgs& args) {
  const auto t0 = Clock::now();
  // 1. The declared case and the measured runs.
  const core::CaseSpec declared = io::read_case(args.case_file);
  io::require_distinct_runs(args.train, "--train");
  io::require_distinct_runs(args.test, "--test");
  io::require_disjoint_runs(args.test, args.train, "--test", "--train",
                            "calibrate --case does not split a run in time (the data-driven "
                            "calibrate, without --case, does: --split-s); hint: test on a run "
                            "that was not trained on");
  std::vector<std::filesystem::path> inputs = io::case_input_files(declared);
  inputs.insert(inputs.end(), args.train.begin(), args.train.end());
  inputs.insert(inputs.end(), args.test.begin(), args.test.end());
  io::OutputDir out(args.out, inputs);  // refused at once, not after the calibration
  std::vector<io::MeasuredRun> train, test;
  for (const auto& f : args.train) train.push_back(io::read_measured_run(f));
  for (const auto& f : args.test) test.push_back(io::read_measured_run(f));
  const auto say = [&](const std::string& what) {
    if (!args.quiet)
      std::cerr << "thermotwin: calibrate: [" << std::lround(seconds_since(t0)) << " s] " << what
                << "\n";
  };
  // 2. The mesh, the channels' readout, the candidates' responses on the training runs.
  say("meshing " + declared.name);
  const mesh::TetMesh mesh = mesh::mesh_case(declared);
  calibration::CalibrationOptions options;
  options.seed = declared.seed;
  if (args.no_refit) options.refit_max_iterations = 0;
  say(std::to_string(mesh.nodes.rows()) +
      " nodes; locating the channels (probes: elastic "
      "influence rows)");
  const calibration::Readout r = calibration::readout(mesh, declared, train.front());
  // The model the candidates' responses are marched on: reduced (its basis holds the channels'
  // Krylov vectors, so that every candidate's response at the channels is kept) unless --full.
  const auto tm = Clock::now();
  say(args.full
          ? "model: full order (" + std::to_string(mesh.nodes.rows()) + " nodes), as --full asks"
          : "model: building the reduced model on the channels (--full for the full order)");
  const calibration::MarchModel model =
      args.full ? calibration::MarchModel(mesh, declared)
                : calibration::MarchModel(mesh, declared, r, solvers::ReductionOptions{});
  nlohmann::json model_json = {{"kind", args.full ? "full" : "reduced"},
                               {"nodes", mesh.nodes.rows()},
                               {"order", model.order()},
                               {"build_s", seconds_since(tm)}};
  if (model.is_reduced()) {
    say("model: reduced, order " + std::to_string(model.order()) + " of " +
        std::to_string(mesh.nodes.rows()) + " nodes");
    // Trust: the full-order residual of the declared model's base state on the first training
    // run, at a few output steps (backward Euler only).
    const core::CaseSpec first = calibration::case_for_run(declared, train.front());
    if (first.thermal.scheme == core::TimeScheme::backward_euler) {
      const auto ind = solvers::twin_indicator(model.full(), *model.reduced(), first, 3);
      model_json["indicator"] = indicator_report(ind, train.front().run);
    }
  }
  say(std::to_string(r.channels()) + " channels, responses on " + std::to_string(train.size()) +
      " training runs");
  const solvers::Progress progress = [&](double t, double end) {
    if (!args.quiet) report_progress("calibrate responses", t, end);
  };
  const calibration::Catalogue cat =
      calibration::catalogue(model, declared, r, train, options, false, progress);
  say(std::to_string(cat.candidates.size()) + " candidate effects; choosing, then the test runs");
  // 3. Choose the effect, write it into the case, evaluate on the test runs.
  const calibration::CalibrationResult res =
      calibration::calibrate(model, declared, cat, test, options);
  // 4. Outputs, all or nothing.
  const auto& dir = out.path();
  std::vector<std::string> train_names;
  for (const auto& t : train) train_names.push_back(t.run);
  nlohmann::json j = calibration::calibration_json(res, r, train_names);
  std::filesystem::create_directories(dir / "augmented");
  nlohmann::json corrections = nlohmann::json::array();
  nlohmann::json files = nlohmann::json::array();
  for (size_t k = 0; k < res.tests.size(); ++k) {
    const auto& t = res.tests[k];
    const std::string toml = io::resolved_case_toml(t.augmented.spec);
    const auto name = "augmented/" + file_name(t.name) + ".toml";
    write_text(dir / name, toml);
    if (k == 0) write_text(dir / "augmented_case.toml", toml);
    files.push_back({{"run", t.name}, {"case", name}});
    for (const auto& c : t.augmented.sensors)
      corrections.push_back(
          {{"run", t.name}, {"sensor", c.sensor}, {"offset_K", c.offset_K}, {"lag_s", c.lag_s}});
  }
  j["augmented_cases"] = files;
  j["sensor_corrections"] = corrections;
  j["runtime_s"] = std::chrono::duration<double>(Clock::now() - t0).count();
  j["model"] = model_json;
  io::write_json(dir / "sensor_corrections.json", corrections);
  io::write_json(dir / "calibration.json", j);

  // Residual table for the figures: before, after, and the effect (before - after) per sample.
  std::ostringstream csv;
  csv << "run,channel,unit,time_s,before,after,effect\n";
  for (const auto& t : res.tests)
    for (int c = 0; c < r.channels(); ++c) {
      const bool temp = c < r.sensors;
      const double s = temp ? 1.0 : 1e6;
      for (Eigen::Index i = 0; i < t.times.size(); ++i) {
        const double m = t.measured(i, c);
        if (!std::isfinite(m)) continue;
        csv << '"' << t.name << "\"," << r.ids[c] << ',' << (temp ? "K" : "um") << ',' << t.times(i)
            << ',' << s * (m - t.before(i, c)) << ',' << s * (m - t.after(i, c)) << ','
            << s * (t.after(i, c) - t.before(i, c)) << '\n';
      }
    }
  write_text(dir / "residuals.csv", csv.str());
  plot({"residuals", (dir / "residuals.csv").string(), (dir / "residual_before_after.png").string(),
        "--effect-out=" + (dir / "effect.png").string()});

  std::ostringstream md;
  md << "# Calibration of " << declared.name << "\n\n";
  md << "Training runs: ";
  for (const auto& n : train_names) md << "`" << n << "` ";
  md << "\n\nTest runs: ";
  for (const auto& t : res.tests) md << "`" << t.name << "` ";
  md << "\n\nModel marched: "
     << (model.is_reduced() ? "reduced, order " + std::to_string(model.order()) + " of " +
                                  std::to_string(mesh.nodes.rows()) + " nodes"
                            : "full order, " + std::to_string(mesh.nodes.rows()) + " nodes")
     << " (`model` in calibration.json).";
  md << "\n\n| | temperature RMS [K] | displacement RMS [um] |\n| --- | --- | --- |\n";
  md << "| before | " << res.before.temperature_rms_K << " | " << res.before.displacement_rms_um
     << " |\n";
  md << "| after | " << res.after.temperature_rms_K << " | " << res.after.displacement_rms_um
     << " |\n\n";
  if (!res.ambiguous.empty()) {
    md << "## Ambiguous\n\n";
    for (const auto& a : res.ambiguous) {
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
  if (res.effects.empty()) {
    if (res.ambiguous.empty())
      md << "No effect claimed: no physical candidate's held-out gain beat both the noise "
            "threshold ("
         << res.selection.null_score << ") and its model-form floor.\n\n";
  } else {
    md << "## Claimed effects\n\n";
    for (const auto& e : res.effects)
      md << "- **" << e["kind"].get<std::string>() << "**: " << e["name"].get<std::string>()
         << "; explained fraction " << e["explained_fraction"].get<double>() << "; score "
         << e["score"].get<double>() << " (noise threshold " << res.selection.null_score
         << ", floor " << e["model_form_floor"].get<double>() << ")\n  - parameters: `"
         << e["parameters"].dump() << "`\n  - location: `" << e["location"].dump() << "`\n";
    for (const auto& e : res.effects)
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
  for (const auto& e : res.refit_rejected)
    md << "- not claimed: " << e["name"].get<std::string>() << ", whose size refitted about "
       << "the updated model is unphysical (" << e.value("unphysical", "") << ")\n";
  md << "\n## Runners-up\n\nA candidate marked unphysical needs a value outside its bounds "
        "(docs/calibration.md) to fit and is never claimed, however well it scores.\n\n"
        "| kind | name | explained fraction | score | unphysical |\n| --- | --- | --- | --- | --- "
        "|\n";
  for (const auto& e : res.runners_up)
    md << "| " << e["kind"].get<std::string>() << " | " << e["name"].get<std::string>() << " | "
       << e["explained_fraction"].get<double>() << " | " << e["score"].get<double>() << " | "
       << e.value("unphysical", "") << " |\n";
  md << "\n## Figures\n\n![residual before and after](residual_before_after.png)\n\n![identified "
        "effect](effect.png)\n\n";
  md << "The augmented case for each test run is in `augmented/`; `augmented_case.toml` is the "
        "first. Sensor offsets "
        "and lags, which a case file cannot declare, are in `sensor_corrections.json` and are "
        "applied to the "
        "simulated readings. See docs/calibration.md.\n";
  write_text(dir / "report.md", md.str());
  out.commit();
  std::cerr << "thermotwin: calibrate: before T " << res.before.temperature_rms_K << " K, u "
            << res.before.displacement_rms_um << " um; after T " << res.after.temperature_rms_K
            << " K, u " << res.after.displacement_rms_um << " um; " << res.effects.size()
            << " effect(s) -> " << args.out.string() << "\n";
  return 0;
}

}  // namespace tt::app
