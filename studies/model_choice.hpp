// The thermal model a study steps: a reduced model the caller read from a file (--rom), the full
// model (--full), or a reduced model built on the fly (the default); and what was stepped, for the
// report (io/model_out.hpp writes it and the indicator's warning).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/campaign.hpp"
#include "solvers/reduction.hpp"
#include "solvers/twin.hpp"
#include "studies/progress.hpp"

namespace tt::studies {

/// Which model to step. `given`, when set (and not `full`), is a reduced model read from
/// `rom_file` and built from the case `built_from`; it must outlive the call.
struct ModelRequest {
  bool full = false;
  const solvers::Twin* given = nullptr;
  std::filesystem::path rom_file{};
  std::string built_from{};
};

/// The reduced model's error indicator: the full-order residual at a few output steps of `run`.
struct IndicatorCheck {
  std::string run;
  solvers::ErrorIndicator indicator;
};

/// What a study stepped.
struct ModelUsed {
  bool reduced = false;
  Eigen::Index nodes = 0;
  int order = 0;       /// reduced states, or the nodes in full order
  double build_s = 0;  /// time to build (assemble, reduce) [s]; 0 for a model read from a file
  std::filesystem::path rom_file;  /// the reduced model's file when one was given, else empty
  std::string built_from;          /// the case that file's model was built from
  std::optional<IndicatorCheck> indicator;
};

struct CampaignOnModel {
  std::vector<solvers::CampaignResult> results;
  ModelUsed model;
  /// The reduced model built here and stepped (empty in full order, and when the request gave
  /// one: that stays the caller's).
  std::optional<solvers::Twin> built;
};

/// Runs the campaign on the requested model, saying which one; a reduced model's indicator is
/// checked on the first run (backward Euler only; each distinct step size and horizon costs a
/// full factor, so few samples).
CampaignOnModel campaign_on_model(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                  const std::vector<solvers::CampaignRun>& runs,
                                  const ModelRequest& request,
                                  const std::vector<int>& sampled_nodes, const Progress& say,
                                  const solvers::Progress& stepping);

}  // namespace tt::studies
