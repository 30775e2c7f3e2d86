// One run of the virtual machine on a meshed case: temperatures, displacements, thermal error.
#pragma once

#include <optional>

#include "solvers/elastic.hpp"
#include "solvers/thermal.hpp"
#include "solvers/thermal_error.hpp"
#include "solvers/twin.hpp"

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
VirtualRun simulate(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                    const Progress& progress = {}, const Checkpointing& checkpointing = {});

/// The same run with the thermal transient from a twin (reduced order) instead: the states at the
/// output times reconstructed to nodal temperatures (T = V z), the energy balance on them, then
/// thermo-elasticity as in simulate. Throws SolverError when the twin was built for another
/// system (check_reducible).
VirtualRun simulate_reduced(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const Twin& twin,
                            const Progress& progress = {});

/// A reduced run recomputed in full at its output times.
struct ReducedCheck {
  double max_temperature_error_k = 0;  /// over every node and output time [K]
  double max_point_error_k = 0;        /// over the named points [K]
  Eigen::Vector3d tcp_error_m =
      Eigen::Vector3d::Zero();                           /// largest |dx|, |dy|, |dz| difference [m]
  Eigen::Vector3d tcp_peak_m = Eigen::Vector3d::Zero();  /// the full run's largest |dx|, |dy|, |dz|
  double full_s = 0;                                     /// wall time of the full recomputation [s]
};

/// Runs `spec` in full order (thermal, and elastic when the reduced run has it) and compares.
ReducedCheck verify_reduced(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                            const VirtualRun& reduced);

}  // namespace tt::solvers
