// One run of the virtual machine, as `thermotwin run` makes it: the thermal transient in full or
// reduced order, thermo-elasticity, the thermal error at the TCP and along the feed axis, the
// reduced model's own error indicator and, when asked, its full-order check. SI units.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "solvers/axis_error.hpp"
#include "solvers/virtual_machine.hpp"
#include "studies/histories.hpp"

namespace tt::studies {

struct VirtualRunOptions {
  /// the reduced model to step; nullptr: the full model
  const solvers::Twin* twin = nullptr;
  /// recompute a reduced run's output times in full and compare
  bool verify = false;
  solvers::Progress progress;
  /// receives a line when a stage without time steps starts (the full-order check)
  std::function<void(const std::string&)> say;
  /// saves (and resumes) the full model's time loop; unused with a twin
  solvers::Checkpointing checkpointing;
};

struct VirtualRunReport {
  solvers::VirtualRun run;
  /// the case's candidate sensors when it asks for surface candidates (their histories are kept)
  std::optional<CandidateSet> candidates;
  /// a reduced run's indicator (backward Euler only; nullopt otherwise)
  std::optional<solvers::ErrorIndicator> indicator;
  std::optional<solvers::ReducedCheck> check;
  /// the feed axis's error at its measurement points, and its compensation polynomial
  std::optional<solvers::AxisError> axis;
  std::optional<solvers::AxisPolynomial> axis_polynomial;
  /// wall time of the simulation [s]
  double simulate_s = 0;
};

/// Throws what the solvers throw (a twin built for another system: SolverError).
VirtualRunReport virtual_run(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                             const VirtualRunOptions& options);

}  // namespace tt::studies
