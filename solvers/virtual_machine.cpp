#include "solvers/virtual_machine.hpp"

#include <chrono>

namespace tt::solvers {

VirtualRun simulate(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const Progress& progress,
                    const Checkpointing& checkpointing) {
  VirtualRun run;
  const auto t0 = std::chrono::steady_clock::now();
  run.operators = thermal_system(mesh, spec);
  run.operators_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  run.thermal = thermal_history(mesh, spec, run.operators, progress, checkpointing);
  run.thermal.timings.assemble_s = run.operators_s;
  if (spec.mechanical.enabled) {
    run.elastic = elastic_history(mesh, spec, run.thermal.temperature);
    if (!spec.mechanical.tcp_point.empty()) run.error = thermal_error(mesh, spec, run.elastic->displacement);
  }
  return run;
}

}  // namespace tt::solvers
