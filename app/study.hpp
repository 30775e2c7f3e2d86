// Adapters between the virtual machine's results and the matrix-only modules (placement,
// fitting): which named points are candidate sensors, and their histories as those modules
// take them.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/campaign.hpp"
#include "solvers/reduction.hpp"

namespace tt::app {

/// Candidate sensors with their histories and the case's targets (mechanical.targets: "dy" and
/// "dz" unless the case says otherwise).
struct Histories {
  std::vector<std::string> names;         /// #candidates point ids, "v<node>" for surface vertices
  std::vector<int> nodes;                 /// #candidates mesh node, -1 when not known
  Eigen::MatrixX3d positions;             /// #candidates x 3 [m]
  Eigen::VectorXd times;                  /// #times [s]
  Eigen::MatrixXd temperature;            /// #times x #candidates [K]
  std::vector<std::string> target_names;  /// #targets: "dx", "dy" or "dz"
  Eigen::MatrixXd targets;                /// #times x #targets thermal error at the TCP [m]
};

/// Named points that are candidate sensors: placement.points when the case lists them, else every
/// named point but the TCP, the probe points and the feed axis's measurement points.
std::vector<int> candidate_points(const core::CaseSpec& spec);

/// The candidate sensors of a meshed case as [placement] chooses them, in column order.
struct CandidateSet {
  std::vector<std::string> names;  /// named point ids, then "v<node>" for surface vertices
  std::vector<int> nodes;          /// mesh node of each (index into mesh.vtu's points)
  Eigen::MatrixX3d positions;      /// #candidates x 3 [m]
};

/// candidates = "points": candidate_points. "surface": the named points in placement.points, then
/// the corner vertices of the chosen bodies' exterior and groups' faces (mesh::surface_vertices),
/// thinned to placement.max_candidates when that is set; a vertex that is a listed named point
/// appears once, under the point's id. Throws CaseError when a named point's id clashes with a
/// vertex's name or the set is empty.
CandidateSet candidate_set(const core::CaseSpec& spec, const mesh::TetMesh& mesh);

/// Run-directory files of the surface candidates (written by `run` when candidates = "surface").
inline constexpr const char* kCandidatesCsv = "candidates.csv";
inline constexpr const char* kCandidateTemperaturesCsv = "candidate_temperatures.csv";

/// Column of ThermalError::values for a target name ("dx", "dy", "dz"); throws CaseError otherwise.
int target_column(const std::string& target);

/// From a run directory: case.resolved.toml, thermal_error.csv and the candidates' histories:
/// temperatures.csv (named points), or candidates.csv and candidate_temperatures.csv when the
/// case asks for surface candidates. Throws DataError when those files are missing.
Histories histories_from_run(const std::filesystem::path& run_dir);

/// From a simulated run's histories at the candidates' nodes (#times x #candidates [K]).
Histories histories_from_nodes(const core::CaseSpec& spec, const CandidateSet& candidates,
                               const std::vector<double>& times,
                               const Eigen::MatrixXd& node_temperature,
                               const Eigen::MatrixXd& error);

/// From a simulated campaign run (point temperatures #times x #named points, error #times x 9).
Histories histories_from_points(const core::CaseSpec& spec, const std::vector<double>& times,
                                const Eigen::MatrixXd& point_temperature,
                                const Eigen::MatrixXd& error);

/// Which thermal model a study steps: a reduced model read from `rom`, the full model when
/// `full`, else a reduced model built on the fly from the case.
struct ModelChoice {
  std::filesystem::path rom;
  bool full = false;
};

/// A campaign's results on the chosen model, and what was used (for the report: "kind" full or
/// reduced, its order and where it came from).
/// The reduced model's error indicator on `run` for summary files (`max_K`, `tolerance_K`,
/// `above_tolerance`); above its tolerance it also warns on stderr.
nlohmann::json indicator_report(const solvers::ErrorIndicator& indicator, const std::string& run);

struct CampaignOnModel {
  std::vector<solvers::CampaignResult> results;
  nlohmann::json model;
};

/// Runs the campaign on the model `choice` names (app/model_choice.cpp), saying on stderr which one
/// (unless quiet). Throws DataError when a reduced model given was built for another machine or
/// mesh.
CampaignOnModel campaign_on_model(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                  const std::vector<solvers::CampaignRun>& runs,
                                  const ModelChoice& choice, const std::vector<int>& sampled_nodes,
                                  bool quiet);

}  // namespace tt::app
