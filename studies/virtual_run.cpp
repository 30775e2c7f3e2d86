#include "studies/virtual_run.hpp"

#include <chrono>

#include "core/timing.hpp"

namespace tt::studies {

VirtualRunReport virtual_run(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                             const VirtualRunOptions& options) {
  VirtualRunReport r;
  if (spec.placement.surface()) r.candidates = candidate_set(spec, mesh);
  const auto t0 = std::chrono::steady_clock::now();
  r.run = options.twin ? solvers::simulate_reduced(mesh, spec, *options.twin, options.progress)
                       : solvers::simulate(mesh, spec, options.progress, options.checkpointing);
  r.simulate_s = core::seconds_since(t0);
  // The reduced run's own error indicator: the full-order residual at sampled output steps.
  if (options.twin && spec.thermal.scheme == core::TimeScheme::backward_euler)
    r.indicator = solvers::twin_indicator(r.run.operators, options.twin->model, spec);
  if (options.verify) {
    if (options.say) options.say("--verify: recomputing the output times in full");
    r.check = solvers::verify_reduced(mesh, spec, r.run);
  }
  if (r.run.elastic && !spec.mechanical.axis_points.empty()) {
    r.axis = solvers::axis_error(mesh, spec, r.run.elastic->displacement);
    r.axis_polynomial = solvers::axis_polynomial(*r.axis, spec.mechanical.axis_polynomial_degree);
  }
  return r;
}

}  // namespace tt::studies
