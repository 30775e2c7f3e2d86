#include "solvers/virtual_machine.hpp"

#include <algorithm>
#include <chrono>

namespace tt::solvers {

namespace {

/// A run with its full system assembled (and timed), before any time loop.
VirtualRun assembled_run(const mesh::TetMesh& mesh, const core::CaseSpec& spec) {
  VirtualRun run;
  const auto t0 = std::chrono::steady_clock::now();
  run.operators = thermal_system(mesh, spec);
  run.operators_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

/// Thermo-elasticity on the run's temperatures, and the thermal error at the tool.
void add_displacements(const mesh::TetMesh& mesh, const core::CaseSpec& spec, VirtualRun& run) {
  run.thermal.timings.assemble_s = run.operators_s;
  if (!spec.mechanical.enabled) return;
  run.elastic = elastic_history(mesh, spec, run.thermal.temperature);
  if (!spec.mechanical.tcp_point.empty())
    run.error = thermal_error(mesh, spec, run.elastic->displacement);
}

}  // namespace

VirtualRun simulate(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const Progress& progress,
                    const Checkpointing& checkpointing) {
  VirtualRun run = assembled_run(mesh, spec);
  run.thermal = thermal_history(mesh, spec, run.operators, progress, checkpointing);
  add_displacements(mesh, spec, run);
  return run;
}

VirtualRun simulate_reduced(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const Twin& twin,
                            const Progress& progress) {
  VirtualRun run = assembled_run(mesh, spec);
  check_reducible(twin.model, run.operators, spec);
  const TwinRun reduced = twin_run(twin, spec, progress);
  run.thermal.times = reduced.times;
  run.thermal.temperature = reconstructed(twin.model, reduced.states);
  run.thermal.timings = reduced.timings;
  run.thermal.energy.heat_in = reduced.heat_in;
  run.thermal.energy.lost = reduced.lost;
  run.thermal.energy.stored =
      stored_heat(mesh, spec, run.thermal.temperature.col(run.thermal.temperature.cols() - 1));
  run.thermal.energy.heat_in_law = heat_in_law(spec, run.operators);
  add_displacements(mesh, spec, run);
  return run;
}

ReducedCheck verify_reduced(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                            const VirtualRun& reduced) {
  const auto t0 = std::chrono::steady_clock::now();
  const ThermalHistory full = thermal_history(mesh, spec, reduced.operators);
  ReducedCheck c;
  const Eigen::MatrixXd diff = (full.temperature - reduced.thermal.temperature).cwiseAbs();
  c.max_temperature_error_k = diff.maxCoeff();
  for (const auto& p : mesh.points)
    c.max_point_error_k = std::max(c.max_point_error_k, diff.row(p.node).maxCoeff());
  if (reduced.error) {
    const ElasticHistory elastic = elastic_history(mesh, spec, full.temperature);
    const ThermalError e = thermal_error(mesh, spec, elastic.displacement);
    for (int d = 0; d < 3; ++d) {
      c.tcp_error_m(d) = (e.values.col(d) - reduced.error->values.col(d)).cwiseAbs().maxCoeff();
      c.tcp_peak_m(d) = e.values.col(d).cwiseAbs().maxCoeff();
    }
  }
  c.full_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return c;
}

}  // namespace tt::solvers
