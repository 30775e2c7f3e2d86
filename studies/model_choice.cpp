#include "studies/model_choice.hpp"

#include "core/timing.hpp"

namespace tt::studies {
namespace {

/// The indicator of `model` on the first run, when its scheme allows it.
std::optional<IndicatorCheck> indicator_check(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                              const std::vector<solvers::CampaignRun>& runs,
                                              const solvers::ReducedModel& model,
                                              std::optional<solvers::FullThermalSystem>& full) {
  if (spec.thermal.scheme != core::TimeScheme::backward_euler || runs.empty()) return {};
  if (!full) full = solvers::thermal_system(mesh, spec);
  return IndicatorCheck{runs.front().name,
                        solvers::twin_indicator(*full, model, runs.front().spec, 3)};
}

}  // namespace

CampaignOnModel campaign_on_model(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                  const std::vector<solvers::CampaignRun>& runs,
                                  const ModelRequest& request,
                                  const std::vector<int>& sampled_nodes, const Progress& say,
                                  const solvers::Progress& stepping) {
  const auto tell = [&](const std::string& line) {
    if (say) say(line);
  };
  CampaignOnModel out;
  out.model.nodes = mesh.nodes.rows();
  if (request.full) {
    tell("model: full order (" + std::to_string(mesh.nodes.rows()) + " nodes), as --full asks");
    out.results = solvers::simulate_campaign(mesh, spec, runs, stepping, sampled_nodes);
    out.model.order = static_cast<int>(mesh.nodes.rows());
    return out;
  }
  std::optional<solvers::Twin> built;
  std::optional<solvers::FullThermalSystem> full_system;  // assembled once: twin and indicator
  const solvers::Twin* twin = request.given;
  if (twin) {
    out.model.rom_file = request.rom_file;
    out.model.built_from = request.built_from;
  } else {
    tell("model: building the reduced model (--full for the full order)");
    const auto t0 = std::chrono::steady_clock::now();
    full_system = solvers::thermal_system(mesh, spec);
    built = solvers::case_twin(mesh, spec, *full_system);
    twin = &*built;
    out.model.build_s = core::seconds_since(t0);
  }
  out.model.reduced = true;
  out.model.order = twin->model.states();
  tell("model: reduced, order " + std::to_string(twin->model.states()) + " of " +
       std::to_string(mesh.nodes.rows()) + " nodes");
  out.results = solvers::twin_campaign(*twin, runs, stepping, sampled_nodes);
  out.model.indicator = indicator_check(mesh, spec, runs, twin->model, full_system);
  out.built = std::move(built);
  return out;
}

}  // namespace tt::studies
