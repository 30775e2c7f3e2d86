#include "solvers/thermal_error.hpp"

#include "core/errors.hpp"

namespace tt::solvers {

ThermalError thermal_error(const mesh::TetMesh& m, const core::CaseSpec& spec, const Eigen::MatrixXd& u) {
  auto node_of = [&](const std::string& id) {
    const int node = mesh::named_node(m, id);
    if (node < 0) throw core::SolverError("mechanical point '" + id + "' is not a named point of the mesh");
    return node;
  };
  const int tcp = node_of(spec.mechanical.tcp_point);
  if (spec.mechanical.probe_points.size() != 2)
    throw core::SolverError("mechanical.probes must name two points, got " +
                            std::to_string(spec.mechanical.probe_points.size()));
  const int z1 = node_of(spec.mechanical.probe_points[0]);
  const int z2 = node_of(spec.mechanical.probe_points[1]);
  ThermalError e;
  e.probe_distance = (m.nodes.row(z2) - m.nodes.row(z1)).norm();
  const Eigen::Index nt = u.cols();
  e.values.resize(nt, kThermalErrorColumns);
  for (Eigen::Index t = 0; t < nt; ++t) {
    auto rel = [&](int node, int d) { return u(3 * node + d, t) - u(3 * node + d, 0); };
    e.values(t, kDx) = rel(tcp, 0);
    e.values(t, kDy) = rel(tcp, 1);
    e.values(t, kDz) = rel(tcp, 2);
    e.values(t, kDxZ1) = rel(z1, 0);
    e.values(t, kDyZ1) = rel(z1, 1);
    e.values(t, kDxZ2) = rel(z2, 0);
    e.values(t, kDyZ2) = rel(z2, 1);
    e.values(t, kTiltX) = -(rel(z2, 1) - rel(z1, 1)) / e.probe_distance;
    e.values(t, kTiltY) = (rel(z2, 0) - rel(z1, 0)) / e.probe_distance;
  }
  return e;
}

}  // namespace tt::solvers
