// thermotwin fit: how well a thermal-error model fed by m sensors predicts the drift on duty
// cycles it was not fitted on (DB3401/T 326-2024 metrics S, S_M, S_sigma).
//   thermotwin fit CASE --out DIR [--hours 5] [--required-sm-um 1] [--quick] [--network]
//                       [--rom DIR | --full] [--estimation]
// 1. The case and its mesh. 2. The virtual test campaign (solvers::campaign_runs) on the chosen
// thermal model (with --estimation, its reduced model also places for estimation in 3). 3. The
// study: studies/fit_on_campaign.hpp. 4. The files (fit.json, modelling_record.{json,md},
// compensation.csv, sensor_count_<target>.csv/.png, held_out/<group>_temperatures.csv; axis_fit.md
// on a case with feed-axis points; the networks' .pt files with --network):
// io/fit_campaign_out.hpp.
#include <iostream>

#include "app/commands.hpp"
#include "app/study.hpp"
#include "io/atomic_dir.hpp"
#include "io/case_reader.hpp"
#include "io/fit_campaign_out.hpp"
#include "mesh/mesher.hpp"
#include "studies/fit_on_campaign.hpp"

namespace tt::app {

int fit_command(const FitArgs& args) {
  const core::CaseSpec spec = io::read_case(args.case_file);
  std::vector<std::filesystem::path> inputs = io::case_input_files(spec);
  if (!args.rom.empty()) inputs.push_back(args.rom);
  io::OutputDir out(args.out, inputs);  // refused at once, not after the work
  const mesh::TetMesh mesh = mesh::mesh_case(spec);
  const auto runs = solvers::campaign_runs(spec, args.hours, spec.seed);
  CampaignOnModel campaign =
      campaign_on_model(mesh, spec, runs, {args.rom, args.full}, {}, args.quiet);
  if (!args.estimation) campaign.twin.reset();  // its basis is #nodes x order: not kept unused
  if (args.estimation && !args.quiet)
    std::cerr << "thermotwin: fit: placement and models; placement for estimation steps the "
                 "observer on the reduced model (order "
              << (campaign.twin ? campaign.twin->model.states() : 0)
              << ") over the fitting runs first\n";
  const auto progress = [&](const std::string& line) {
    if (!args.quiet) std::cerr << "thermotwin: fit: " << line << "\n";
  };
  const studies::CampaignFitReport report =
      studies::fit_on_campaign(spec, campaign.results,
                               {args.quick, args.network, args.required_sm_um * 1e-6,
                                campaign.twin ? &*campaign.twin : nullptr, &runs, progress});
  io::write_campaign_fit(out.path(), spec, runs, report, campaign.model);
  out.commit();
  std::cerr << "thermotwin: fit: " << io::campaign_fit_summary(report).dump() << "\n";
  return 0;
}

}  // namespace tt::app
