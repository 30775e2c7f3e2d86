// The CLI's adapters around the studies: a run directory's histories (app/run_histories.cpp) and
// the thermal model a study steps (app/model_choice.cpp: --rom read, then
// studies/model_choice.hpp's choice, its report written by io/model_out.hpp). Which points are
// candidates and their histories are studies/histories.hpp's.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/campaign.hpp"
#include "solvers/reduction.hpp"
#include "solvers/twin.hpp"
#include "studies/histories.hpp"

namespace tt::app {

using studies::candidate_points;
using studies::candidate_set;
using studies::CandidateSet;
using studies::Histories;
using studies::histories_from_nodes;
using studies::histories_from_points;
using studies::target_column;

/// From a run directory: case.resolved.toml, thermal_error.csv and the candidates' histories:
/// temperatures.csv (named points), or candidates.csv and candidate_temperatures.csv when the
/// case asks for surface candidates. Throws DataError when those files are missing.
Histories histories_from_run(const std::filesystem::path& run_dir);

/// Which thermal model a study steps: a reduced model read from `rom`, the full model when
/// `full`, else a reduced model built on the fly from the case.
struct ModelChoice {
  std::filesystem::path rom;
  bool full = false;
};

/// A campaign's results on the chosen model, and what was used (for the report: "kind" full or
/// reduced, its order and where it came from; io::campaign_model_json).
struct CampaignOnModel {
  std::vector<solvers::CampaignResult> results;
  nlohmann::json model;
  /// The reduced model the campaign stepped (read from --rom or built); empty in full order.
  std::optional<solvers::Twin> twin;
};

/// Runs the campaign on the model `choice` names (app/model_choice.cpp), saying on stderr which one
/// (unless quiet). Throws DataError when a reduced model given was built for another machine or
/// mesh.
CampaignOnModel campaign_on_model(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                  const std::vector<solvers::CampaignRun>& runs,
                                  const ModelChoice& choice, const std::vector<int>& sampled_nodes,
                                  bool quiet);

}  // namespace tt::app
