#include "solvers/thermal_error.hpp"

#include "core/errors.hpp"
#include "core/finite.hpp"

namespace tt::solvers {

std::array<int, 3> error_nodes(const mesh::TetMesh& m, const core::CaseSpec& spec) {
  auto node_of = [&](const std::string& id) {
    const int node = mesh::named_node(m, id);
    if (node < 0)
      throw core::SolverError("mechanical point '" + id + "' is not a named point of the mesh");
    return node;
  };
  if (spec.mechanical.probe_points.size() != 2)
    throw core::SolverError("mechanical.probes must name two points, got " +
                            std::to_string(spec.mechanical.probe_points.size()));
  return {node_of(spec.mechanical.tcp_point), node_of(spec.mechanical.probe_points[0]),
          node_of(spec.mechanical.probe_points[1])};
}

ThermalError thermal_error_of(const Eigen::MatrixXd& u, double probe_distance) {
  ThermalError e;
  e.probe_distance = probe_distance;
  const Eigen::Index nt = u.cols();
  e.values.resize(nt, kThermalErrorColumns);
  for (Eigen::Index t = 0; t < nt; ++t) {
    auto rel = [&](int point, int d) { return u(3 * point + d, t) - u(3 * point + d, 0); };
    e.values(t, kDx) = rel(0, 0);
    e.values(t, kDy) = rel(0, 1);
    e.values(t, kDz) = rel(0, 2);
    e.values(t, kDxZ1) = rel(1, 0);
    e.values(t, kDyZ1) = rel(1, 1);
    e.values(t, kDxZ2) = rel(2, 0);
    e.values(t, kDyZ2) = rel(2, 1);
    e.values(t, kTiltX) = -(rel(2, 1) - rel(1, 1)) / probe_distance;
    e.values(t, kTiltY) = (rel(2, 0) - rel(1, 0)) / probe_distance;
  }
  return e;
}

ThermalError thermal_error(const mesh::TetMesh& m, const core::CaseSpec& spec,
                           const Eigen::MatrixXd& u) {
  const auto nodes = error_nodes(m, spec);
  Eigen::MatrixXd rows(9, u.cols());
  for (int p = 0; p < 3; ++p)
    for (int d = 0; d < 3; ++d) rows.row(3 * p + d) = u.row(3 * nodes[p] + d);
  ThermalError e = thermal_error_of(rows, (m.nodes.row(nodes[2]) - m.nodes.row(nodes[1])).norm());
  core::require_finite(e.values, "the thermal error (row: output time, column: dx, dy, dz, ...)",
                       "the TCP and probe displacements of " + spec.source.string() +
                           " overflowed; check the heat loads");
  return e;
}

}  // namespace tt::solvers
