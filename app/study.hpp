// Adapters between the virtual machine's results and the matrix-only modules (placement,
// fitting): which named points are candidate sensors, and their histories as those modules
// take them.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "core/case_spec.hpp"

namespace tt::app {

/// Candidate sensors with their histories and the case's targets (mechanical.targets: "dy" and
/// "dz" unless the case says otherwise).
struct Histories {
  std::vector<std::string> names;   /// #candidates point ids
  Eigen::MatrixX3d positions;       /// #candidates x 3 [m]
  Eigen::VectorXd times;            /// #times [s]
  Eigen::MatrixXd temperature;      /// #times x #candidates [K]
  std::vector<std::string> target_names;  /// #targets: "dx", "dy" or "dz"
  Eigen::MatrixXd targets;                /// #times x #targets thermal error at the TCP [m]
};

/// Named points that are candidate sensors: every named point but the TCP, the probe points and
/// the feed axis's measurement points.
std::vector<int> candidate_points(const core::CaseSpec& spec);

/// Column of ThermalError::values for a target name ("dx", "dy", "dz"); throws CaseError otherwise.
int target_column(const std::string& target);

/// From a run directory: case.resolved.toml, temperatures.csv, thermal_error.csv.
Histories histories_from_run(const std::filesystem::path& run_dir);

/// From a simulated campaign run (point temperatures #times x #named points, error #times x 9).
Histories histories_from_points(const core::CaseSpec& spec, const std::vector<double>& times,
                                const Eigen::MatrixXd& point_temperature, const Eigen::MatrixXd& error);

}  // namespace tt::app
