// Candidate sensors of a meshed case and their simulated histories, as the matrix-only modules
// (placement, fitting) take them: which named points or surface vertices are candidates, and the
// case's targets as columns of the thermal error.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"

namespace tt::studies {

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

/// Column of ThermalError::values for a target name ("dx", "dy", "dz"); throws CaseError otherwise.
int target_column(const std::string& target);

/// From a simulated run's histories at the candidates' nodes (#times x #candidates [K]).
Histories histories_from_nodes(const core::CaseSpec& spec, const CandidateSet& candidates,
                               const std::vector<double>& times,
                               const Eigen::MatrixXd& node_temperature,
                               const Eigen::MatrixXd& error);

/// From a simulated campaign run (point temperatures #times x #named points, error #times x 9).
Histories histories_from_points(const core::CaseSpec& spec, const std::vector<double>& times,
                                const Eigen::MatrixXd& point_temperature,
                                const Eigen::MatrixXd& error);

}  // namespace tt::studies
