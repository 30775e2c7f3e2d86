// One run of the virtual machine on a meshed case: temperatures, displacements, thermal error.
#pragma once

#include <optional>

#include "solvers/elastic.hpp"
#include "solvers/thermal.hpp"
#include "solvers/thermal_error.hpp"

namespace tt::solvers {

struct VirtualRun {
  FullThermalSystem operators;
  ThermalHistory thermal;
  std::optional<ElasticHistory> elastic;  /// when mechanical.enabled
  std::optional<ThermalError> error;      /// when mechanical.enabled and a TCP is named
  double operators_s = 0;
};

/// Thermal transient, then (if enabled) thermo-elastic displacements at every output time.
/// `checkpointing` saves (and resumes) the thermal time loop's state.
VirtualRun simulate(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const Progress& progress = {},
                    const Checkpointing& checkpointing = {});

}  // namespace tt::solvers
