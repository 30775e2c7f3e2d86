#include "studies/histories.hpp"

#include <algorithm>

#include "core/directions.hpp"
#include "core/errors.hpp"
#include "mesh/surface_vertices.hpp"
#include "solvers/thermal_error.hpp"

namespace tt::studies {

namespace {

int point_index(const core::CaseSpec& spec, const std::string& id) {
  for (size_t i = 0; i < spec.points.size(); ++i)
    if (spec.points[i].id == id) return static_cast<int>(i);
  throw core::CaseError(spec.source.string() + ": placement names point '" + id +
                        "', which the case does not have");
}

/// The case's targets as columns of the thermal error (#times x 9 [m, rad]).
void set_targets(const core::CaseSpec& spec, const Eigen::MatrixXd& error, Histories& h) {
  h.target_names = spec.mechanical.targets;
  h.targets.resize(error.rows(), static_cast<Eigen::Index>(h.target_names.size()));
  for (size_t k = 0; k < h.target_names.size(); ++k)
    h.targets.col(static_cast<Eigen::Index>(k)) = error.col(target_column(h.target_names[k]));
}

}  // namespace

std::vector<int> candidate_points(const core::CaseSpec& spec) {
  std::vector<int> out;
  if (!spec.placement.points.empty()) {
    for (const auto& id : spec.placement.points) out.push_back(point_index(spec, id));
    return out;
  }
  for (size_t i = 0; i < spec.points.size(); ++i) {
    const auto& id = spec.points[i].id;
    const auto& probes = spec.mechanical.probe_points;
    const auto& axis = spec.mechanical.axis_points;
    if (id == spec.mechanical.tcp_point ||
        std::find(probes.begin(), probes.end(), id) != probes.end() ||
        std::find(axis.begin(), axis.end(), id) != axis.end())
      continue;
    out.push_back(static_cast<int>(i));
  }
  if (out.empty())
    throw core::CaseError(spec.source.string() + ": no named points to use as candidate sensors");
  return out;
}

int target_column(const std::string& target) {
  for (int d = 0; d < 3; ++d)  // dx, dy, dz are ThermalError's first three columns
    if (target == core::kDirectionNames[d]) return solvers::kDx + d;
  throw core::CaseError("target '" + target + "': expected \"dx\", \"dy\" or \"dz\"");
}

CandidateSet candidate_set(const core::CaseSpec& spec, const mesh::TetMesh& mesh) {
  CandidateSet set;
  std::vector<Eigen::Vector3d> positions;
  const auto add = [&](const std::string& name, int node) {
    set.names.push_back(name);
    set.nodes.push_back(node);
    positions.push_back(mesh.nodes.row(node).transpose());
  };
  // Named points: all candidates for "points"; only those listed for "surface".
  std::vector<int> named;
  if (!spec.placement.surface())
    named = candidate_points(spec);
  else
    for (const auto& id : spec.placement.points) named.push_back(point_index(spec, id));
  for (int i : named) {
    const int node = mesh::named_node(mesh, spec.points[i].id);
    if (node < 0)
      throw core::MeshError("named point '" + spec.points[i].id + "' is not a vertex of the mesh");
    add(spec.points[i].id, node);
  }
  if (spec.placement.surface()) {
    std::vector<core::RegionId> bodies;
    std::vector<core::BoundaryId> groups;
    for (int b : spec.placement.bodies) bodies.push_back(core::RegionId{b});
    for (int g : spec.placement.groups) groups.push_back(core::BoundaryId{g});
    const auto vertices = mesh::spread_subset(mesh, mesh::surface_vertices(mesh, bodies, groups),
                                              spec.placement.max_candidates);
    const std::vector<int> named_nodes = set.nodes;
    const std::vector<std::string> named_ids = set.names;
    for (int v : vertices) {
      if (std::find(named_nodes.begin(), named_nodes.end(), v) != named_nodes.end()) continue;
      const std::string name = std::string("v").append(std::to_string(v));
      if (std::find(named_ids.begin(), named_ids.end(), name) != named_ids.end())
        throw core::CaseError(spec.source.string() + ": placement.points: point id '" + name +
                              "' is also the name of surface vertex " + std::to_string(v) +
                              "; hint: rename the point");
      add(name, v);
    }
  }
  if (set.names.empty())
    throw core::CaseError(
        spec.source.string() +
        ": placement: no candidate sensors (the chosen surfaces have no vertices)");
  set.positions.resize(static_cast<Eigen::Index>(positions.size()), 3);
  for (size_t c = 0; c < positions.size(); ++c)
    set.positions.row(static_cast<Eigen::Index>(c)) = positions[c].transpose();
  return set;
}

Histories histories_from_nodes(const core::CaseSpec& spec, const CandidateSet& candidates,
                               const std::vector<double>& times,
                               const Eigen::MatrixXd& node_temperature,
                               const Eigen::MatrixXd& error) {
  if (node_temperature.cols() != static_cast<Eigen::Index>(candidates.names.size()) ||
      node_temperature.rows() != static_cast<Eigen::Index>(times.size()) ||
      error.rows() != node_temperature.rows())
    throw core::DataError("candidate histories: " + std::to_string(node_temperature.rows()) +
                          " x " + std::to_string(node_temperature.cols()) + " temperatures for " +
                          std::to_string(times.size()) + " times and " +
                          std::to_string(candidates.names.size()) + " candidates, " +
                          std::to_string(error.rows()) +
                          " error rows: expected one row per time, one column per candidate");
  Histories h;
  h.names = candidates.names;
  h.nodes = candidates.nodes;
  h.positions = candidates.positions;
  h.times =
      Eigen::Map<const Eigen::VectorXd>(times.data(), static_cast<Eigen::Index>(times.size()));
  h.temperature = node_temperature;
  set_targets(spec, error, h);
  return h;
}

Histories histories_from_points(const core::CaseSpec& spec, const std::vector<double>& times,
                                const Eigen::MatrixXd& point_temperature,
                                const Eigen::MatrixXd& error) {
  const std::vector<int> cand = candidate_points(spec);
  Histories h;
  h.times =
      Eigen::Map<const Eigen::VectorXd>(times.data(), static_cast<Eigen::Index>(times.size()));
  h.positions.resize(static_cast<Eigen::Index>(cand.size()), 3);
  h.temperature.resize(point_temperature.rows(), static_cast<Eigen::Index>(cand.size()));
  for (size_t c = 0; c < cand.size(); ++c) {
    h.names.push_back(spec.points[cand[c]].id);
    h.nodes.push_back(-1);
    h.positions.row(static_cast<Eigen::Index>(c)) = spec.points[cand[c]].position.transpose();
    h.temperature.col(static_cast<Eigen::Index>(c)) = point_temperature.col(cand[c]);
  }
  set_targets(spec, error, h);
  return h;
}

}  // namespace tt::studies
