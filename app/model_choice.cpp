// The CLI's side of the model a study steps (studies/model_choice.hpp): --rom read and checked
// here, the model described and the indicator's warning written by io/model_out.hpp.
#include <iostream>

#include "app/commands.hpp"
#include "app/study.hpp"
#include "io/model_out.hpp"
#include "io/reduced_model_io.hpp"

namespace tt::app {

CampaignOnModel campaign_on_model(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                  const std::vector<solvers::CampaignRun>& runs,
                                  const ModelChoice& choice, const std::vector<int>& sampled_nodes,
                                  bool quiet) {
  io::ReducedModelFile file;
  studies::ModelRequest request{.full = choice.full};
  if (!choice.full && !choice.rom.empty()) {
    file = io::read_reduced_model(choice.rom);
    io::check_reduced_model_fits(file, io::reduced_model_key(spec, mesh), choice.rom);
    request = {false, &file.twin, choice.rom, file.case_name};
  }
  const auto say = [&](const std::string& what) {
    if (!quiet) std::cerr << "thermotwin: " << what << "\n";
  };
  const solvers::Progress progress = [&](double t, double end) {
    if (!quiet) report_progress("campaign", t, end);
  };
  studies::CampaignOnModel study =
      studies::campaign_on_model(mesh, spec, runs, request, sampled_nodes, say, progress);
  if (study.model.indicator) std::cerr << io::indicator_warning(*study.model.indicator);
  std::optional<solvers::Twin> twin = std::move(study.built);
  if (request.given) twin = std::move(file.twin);
  return {std::move(study.results), io::campaign_model_json(study.model), std::move(twin)};
}

}  // namespace tt::app
