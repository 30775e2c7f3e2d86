// What a reduced-order twin reports and how it is judged: the outputs of a case as rows on the
// temperature field (named points' temperatures; the TCP, probe and axis points' displacements as
// adjoint influence vectors), the same rows projected on a reduced basis, their histories, and the
// comparison of a reduced run with the full one.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/campaign.hpp"
#include "solvers/elastic.hpp"
#include "solvers/reduction.hpp"
#include "solvers/thermal_stepper.hpp"

namespace tt::solvers {

/// Output rows on a temperature field (full: #nodes columns; reduced: #states columns).
struct TwinOutputs {
  std::vector<std::string> names;  /// point ids, then "tcp_dx".."z2_dz", then "<axis id>_dx".."_dz"
  Eigen::MatrixXd rows;            /// #names x #columns: [K per K] then [m per K]
  int temperatures = 0;            /// rows [0, temperatures) are point temperatures
  bool tcp = false;                /// rows [temperatures, temperatures + 9) are the TCP and probes
  double reference_k = 0;          /// stress-free temperature [K]
  double probe_distance = 0;       /// between the two probe points [m]
  /// With tcp, per material of the case (its order; `materials` their names): the part of the
  /// displacement rows (rows [temperatures, #names)) that material's thermal strain makes, so that
  /// its expansion coefficient times (1 + x) adds x times it. The entries sum to those rows. Empty
  /// without tcp (and in reduced models written before they were kept).
  std::vector<Eigen::MatrixXd> expansion;
  std::vector<std::string> materials;
};

/// The row of named point `id`'s temperature in `outputs` (in [0, temperatures)); -1 when the
/// outputs do not name it.
int temperature_row(const TwinOutputs& outputs, const std::string& id);

/// The case's outputs on the full mesh: every named point's temperature, and with `elastic` (the
/// case's factored stiffness; mechanical enabled and a TCP named) the nine TCP/probe influence
/// rows and three per axis point.
TwinOutputs full_outputs(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                         const ElasticModel* elastic);

/// The same rows on another basis: rows * basis (#nodes x r).
TwinOutputs projected_outputs(const TwinOutputs& full, const Eigen::MatrixXd& basis);

/// Output histories: #times x #names, temperatures [K] and displacements relative to the
/// stress-free state [m], from the rows read from the states (rows * states: #names x #times).
/// `uniform` is the state of a uniform 1 K field (ones in full).
Eigen::MatrixXd output_history(const TwinOutputs& out, const Eigen::MatrixXd& readout,
                               const Eigen::VectorXd& uniform);

/// A reduced model with the case's outputs on it.
struct Twin {
  ReducedModel model;
  TwinOutputs outputs;  /// projected on model.basis
};

/// The twin of a case: the full system's reduced model and the case's outputs (full_outputs)
/// projected on it.
Twin build_twin(const FullThermalSystem& full, const core::CaseSpec& spec,
                const TwinOutputs& outputs, const ReductionOptions& options = {});

/// The twin of a meshed case in one call: its full system, the stiffness factored once for the
/// TCP's influence rows (when the case has a TCP), the reduced model and the projected outputs.
Twin case_twin(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
               const ReductionOptions& options = {});
/// The same on the case's full system already assembled (thermal_system(mesh, spec)).
Twin case_twin(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const FullThermalSystem& full,
               const ReductionOptions& options = {});

/// A run of the twin: the case's duty cycle stepped on the reduced states by the one stepper.
struct TwinRun {
  std::vector<double> times;     /// t = 0, then the case's output times [s]
  Eigen::MatrixXd states;        /// #states x #times
  Eigen::MatrixXd outputs;       /// #times x #outputs, as output_history gives
  double heat_in = 0, lost = 0;  /// from the step loads and through the films [J]
  ThermalTimings timings;
};
TwinRun twin_run(const Twin& twin, const core::CaseSpec& spec, const Progress& progress = {});

/// The error indicator of a reduced run of `spec` (the twin's model, or any reduced model): the
/// full-order residual, in kelvin, of the steps that end at up to `samples` output times (spread
/// evenly, the last included). Backward Euler only: for a Crank-Nicolson case it throws SolverError
/// (use run --verify).
ErrorIndicator twin_indicator(const FullThermalSystem& full, const ReducedModel& model,
                              const core::CaseSpec& spec, int samples = 12);

/// The same outputs from the full system (one stepper, full order): #times x #outputs.
Eigen::MatrixXd full_outputs_history(const FullThermalSystem& full, const TwinOutputs& outputs,
                                     const core::CaseSpec& spec, const Progress& progress = {});

/// The largest point-temperature difference a reduced run may show against the full one [K].
inline constexpr double kTwinTemperatureLimitK = 0.01;

/// A reduced run against the full one on the same duty cycle.
struct TwinComparison {
  std::string run, shape;
  double max_temperature_error_k = 0;  /// over the point temperatures and times [K]
  std::string worst_point;             /// where it is largest
  /// Per displacement column (TCP dx, dy, dz, then each axis point's dx, dy, dz, relative to
  /// t = 0): largest difference, the full run's peak |value| and the limit max(1 % peak, 0.02 um).
  std::vector<std::string> drift_names;
  Eigen::VectorXd drift_error_m, drift_peak_m, drift_limit_m;
  bool passes(double temperature_limit_k = kTwinTemperatureLimitK) const;
};

/// Compares output histories of the same run (#times x #names each, as output_history gives).
TwinComparison compare_outputs(const TwinOutputs& out, const Eigen::MatrixXd& full,
                               const Eigen::MatrixXd& reduced);

/// One campaign run read from its output history (#times x #names, as output_history gives) and
/// the sampled nodes' history: the named points' temperatures, the TCP's thermal error and the
/// error at the run's feed-axis points. The one reading of simulate_campaign and twin_campaign.
/// Throws SolverError when `out` has no TCP rows or no rows for an axis point of the run.
CampaignResult campaign_result(const TwinOutputs& out, const CampaignRun& run,
                               const std::vector<double>& times, const Eigen::MatrixXd& history,
                               Eigen::MatrixXd node_temperature);

/// The virtual campaign from the twin: each run stepped on the reduced states and read as
/// simulate_campaign reads the full model (campaign_result; `sampled_nodes` through the basis
/// rows). Throws SolverError when the twin has no TCP rows.
std::vector<CampaignResult> twin_campaign(const Twin& twin, const std::vector<CampaignRun>& runs,
                                          const Progress& progress = {},
                                          const std::vector<int>& sampled_nodes = {});

/// The twin against the full model on each run (full_outputs gives `full_out` on the full mesh;
/// the twin's outputs are the same rows projected): one comparison per run. Progress goes over all
/// runs' simulated time, full and reduced.
std::vector<TwinComparison> validate_twin(const FullThermalSystem& full,
                                          const TwinOutputs& full_out, const Twin& twin,
                                          const std::vector<CampaignRun>& runs,
                                          const Progress& progress = {});

}  // namespace tt::solvers
