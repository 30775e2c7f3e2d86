// The thermal model a study steps: a reduced model from --rom, the full one with --full, or a
// reduced one built on the fly (the default).
#include <chrono>
#include <iostream>
#include <optional>

#include "app/commands.hpp"
#include "app/study.hpp"
#include "io/reduced_model_io.hpp"
#include "solvers/twin.hpp"

namespace tt::app {

nlohmann::json indicator_report(const solvers::ErrorIndicator& ind, const std::string& run) {
  if (ind.above_tolerance())
    std::cerr << "thermotwin: warning: the reduced model's error indicator is " << ind.max_k
              << " K on run '" << run << "', above its tolerance of " << ind.tolerance_k
              << " K: check with --full\n";
  return {{"run", run},
          {"max_K", ind.max_k},
          {"tolerance_K", ind.tolerance_k},
          {"above_tolerance", ind.above_tolerance()}};
}

CampaignOnModel campaign_on_model(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                  const std::vector<solvers::CampaignRun>& runs,
                                  const ModelChoice& choice, const std::vector<int>& sampled_nodes,
                                  bool quiet) {
  const auto say = [&](const std::string& what) {
    if (!quiet) std::cerr << "thermotwin: " << what << "\n";
  };
  const solvers::Progress progress = [&](double t, double end) {
    if (!quiet) report_progress("campaign", t, end);
  };
  CampaignOnModel out;
  if (choice.full) {
    say("model: full order (" + std::to_string(mesh.nodes.rows()) + " nodes), as --full asks");
    out.results = solvers::simulate_campaign(mesh, spec, runs, progress, sampled_nodes);
    out.model = {{"kind", "full"}, {"nodes", mesh.nodes.rows()}};
    return out;
  }
  std::optional<solvers::Twin> built;
  std::optional<solvers::FullThermalSystem> full_system;  // assembled once: twin and indicator
  io::ReducedModelFile file;
  const solvers::Twin* twin = nullptr;
  if (!choice.rom.empty()) {
    file = io::read_reduced_model(choice.rom);
    io::check_reduced_model_fits(file, io::reduced_model_key(spec, mesh), choice.rom);
    twin = &file.twin;
    out.model = {{"kind", "reduced"},
                 {"rom", std::filesystem::absolute(choice.rom).string()},
                 {"built_from", file.case_name}};
  } else {
    say("model: building the reduced model (--full for the full order)");
    const auto t0 = std::chrono::steady_clock::now();
    full_system = solvers::thermal_system(mesh, spec);
    built = solvers::case_twin(mesh, spec, *full_system);
    twin = &*built;
    out.model = {
        {"kind", "reduced"},
        {"rom", "built on the fly"},
        {"build_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
  }
  out.model["order"] = twin->model.states();
  out.model["nodes"] = mesh.nodes.rows();
  say("model: reduced, order " + std::to_string(twin->model.states()) + " of " +
      std::to_string(mesh.nodes.rows()) + " nodes");
  out.results = solvers::twin_campaign(*twin, runs, progress, sampled_nodes);
  // Trust: the full-order residual at a few output steps of the first run (each distinct step
  // size and horizon costs a full factor, so few samples).
  if (spec.thermal.scheme == core::TimeScheme::backward_euler && !runs.empty()) {
    if (!full_system) full_system = solvers::thermal_system(mesh, spec);
    const auto ind = solvers::twin_indicator(*full_system, twin->model, runs.front().spec, 3);
    out.model["indicator"] = indicator_report(ind, runs.front().name);
  }
  return out;
}

}  // namespace tt::app
