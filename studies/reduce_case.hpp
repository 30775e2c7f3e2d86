// The case's reduced-order twin and its judgement against the full model (thermotwin reduce,
// docs/reduced-order.md): the full thermal system and its output rows (the stiffness factored
// once for the TCP's, probes' and axis points' influence rows), the reduced basis with the system
// and the outputs projected on it, and the twin against the full model on duty cycles that were
// not used to build it. SI units.
#pragma once

#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/thermal.hpp"
#include "solvers/twin.hpp"
#include "studies/progress.hpp"

namespace tt::studies {

struct ReduceOptions {
  bool quick_validation = false;  /// validate on the case's own duty cycle only
  Progress say;                   /// a line per stage
  solvers::Progress progress;     /// the validation's full-model runs
};

struct ReduceReport {
  solvers::Twin twin;
  /// one comparison per validation run
  std::vector<solvers::TwinComparison> validation;
  bool passes = true;  /// every validation run within its limits
  /// wall times [s]: output rows (with the factor), basis, validation
  double outputs_s = 0, reduce_s = 0, validate_s = 0;
};

/// Throws what the solvers throw.
ReduceReport reduce_case(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                         const ReduceOptions& options);

}  // namespace tt::studies
