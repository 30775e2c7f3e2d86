#include "studies/reduce_case.hpp"

#include <chrono>
#include <optional>
#include <string>

#include "core/timing.hpp"
#include "solvers/campaign.hpp"

namespace tt::studies {
namespace {

/// The full thermal system's output rows; for the thermal error the stiffness is factored once
/// and dropped before the basis is built (it is the largest thing in memory).
solvers::TwinOutputs output_rows(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                 const Progress& say) {
  std::optional<solvers::ElasticModel> elastic;
  if (spec.mechanical.enabled && !spec.mechanical.tcp_point.empty()) {
    if (say) say("factoring the stiffness for the TCP's influence rows");
    elastic.emplace(mesh, spec);
  }
  return solvers::full_outputs(mesh, spec, elastic ? &*elastic : nullptr);
}

}  // namespace

ReduceReport reduce_case(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                         const ReduceOptions& options) {
  const auto say = [&](const std::string& what) {
    if (options.say) options.say(what);
  };
  ReduceReport report;
  // 1. The full system and its output rows.
  auto t = std::chrono::steady_clock::now();
  const solvers::FullThermalSystem full = solvers::thermal_system(mesh, spec);
  const solvers::TwinOutputs full_out = output_rows(mesh, spec, options.say);
  report.outputs_s = core::seconds_since(t);
  // 2. The reduced model.
  say("building the basis");
  t = std::chrono::steady_clock::now();
  report.twin = solvers::build_twin(full, spec, full_out);
  report.reduce_s = core::seconds_since(t);
  say("order " + std::to_string(report.twin.model.states()) + " (" +
      std::to_string(report.reduce_s) + " s)");
  // 3. The twin against the full model.
  t = std::chrono::steady_clock::now();
  const auto runs = options.quick_validation
                        ? std::vector<solvers::CampaignRun>{{"own_cycle", "the case's own", spec}}
                        : solvers::validation_runs(spec, spec.seed);
  report.validation = solvers::validate_twin(full, full_out, report.twin, runs, options.progress);
  report.validate_s = core::seconds_since(t);
  for (const auto& c : report.validation) {
    report.passes = report.passes && c.passes();
    say(c.run + ": max |dT| " + std::to_string(c.max_temperature_error_k) + " K at " +
        c.worst_point + (c.passes() ? " (within limits)" : " (OUTSIDE the limits)"));
  }
  return report;
}

}  // namespace tt::studies
