#include "solvers/twin.hpp"

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "solvers/loads.hpp"
#include "solvers/thermal.hpp"
#include "solvers/thermal_error.hpp"

namespace tt::solvers {

namespace {

constexpr const char* kTcpNames[9] = {"tcp_dx", "tcp_dy", "tcp_dz", "z1_dx", "z1_dy",
                                      "z1_dz",  "z2_dx",  "z2_dy",  "z2_dz"};
constexpr const char* kAxes = "xyz";

/// Drift columns of an output history: TCP dx, dy, dz and each axis point's dx, dy, dz, relative
/// to the first time [m].
Eigen::MatrixXd drift_columns(const TwinOutputs& out, const Eigen::MatrixXd& history) {
  const Eigen::Index first = out.temperatures;
  const Eigen::Index tcp = out.tcp ? 3 : 0;
  const Eigen::Index axis = static_cast<Eigen::Index>(out.names.size()) - first - (out.tcp ? 9 : 0);
  Eigen::MatrixXd d(history.rows(), tcp + axis);
  if (tcp) d.leftCols(3) = history.middleCols(first, 3);
  if (axis) d.rightCols(axis) = history.rightCols(axis);
  return d.rowwise() - d.row(0);
}

}  // namespace

TwinOutputs full_outputs(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                         const ElasticModel* elastic) {
  TwinOutputs out;
  const Eigen::Index n = mesh.nodes.rows();
  std::vector<Eigen::VectorXd> rows;
  for (const auto& p : mesh.points) {
    out.names.push_back(p.id);
    rows.push_back(Eigen::VectorXd::Unit(n, p.node));
  }
  out.temperatures = static_cast<int>(rows.size());
  if (elastic && spec.mechanical.enabled && !spec.mechanical.tcp_point.empty()) {
    out.tcp = true;
    out.reference_k = elastic->reference_temperature_k();
    const auto nodes = error_nodes(mesh, spec);
    out.probe_distance = (mesh.nodes.row(nodes[2]) - mesh.nodes.row(nodes[1])).norm();
    // Every displacement output is one dof: the influence rows of all of them in one block solve.
    std::vector<std::pair<int, int>> dofs;
    for (int p = 0; p < 3; ++p)
      for (int d = 0; d < 3; ++d) {
        out.names.push_back(kTcpNames[3 * p + d]);
        dofs.emplace_back(nodes[p], d);
      }
    for (const auto& id : spec.mechanical.axis_points) {
      const int node = mesh::named_node(mesh, id);
      if (node < 0)
        throw core::SolverError("axis point '" + id + "' is not a named point of the mesh");
      for (int d = 0; d < 3; ++d) {
        out.names.push_back(id + "_d" + kAxes[d]);
        dofs.emplace_back(node, d);
      }
    }
    ElasticModel::SplitRows influence = elastic->influence_rows_split(dofs, mesh, spec);
    for (Eigen::Index i = 0; i < influence.rows.rows(); ++i)
      rows.push_back(influence.rows.row(i).transpose());
    out.expansion = std::move(influence.by_material);
    for (const core::Material& m : spec.materials) out.materials.push_back(m.name);
  }
  out.rows.resize(static_cast<Eigen::Index>(rows.size()), n);
  for (std::size_t i = 0; i < rows.size(); ++i)
    out.rows.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
  return out;
}

int temperature_row(const TwinOutputs& outputs, const std::string& id) {
  const auto first = outputs.names.begin(), last = first + outputs.temperatures;
  const auto it = std::find(first, last, id);
  return it == last ? -1 : static_cast<int>(it - first);
}

TwinOutputs projected_outputs(const TwinOutputs& full, const Eigen::MatrixXd& basis) {
  if (full.rows.cols() != basis.rows())
    throw core::SolverError("output rows have " + std::to_string(full.rows.cols()) +
                            " columns, the basis " + std::to_string(basis.rows()) +
                            " rows: built for another mesh");
  TwinOutputs out = full;
  out.rows = full.rows * basis;
  for (Eigen::MatrixXd& part : out.expansion) part = part * basis;
  return out;
}

Eigen::MatrixXd output_history(const TwinOutputs& out, const Eigen::MatrixXd& readout,
                               const Eigen::VectorXd& uniform) {
  Eigen::MatrixXd h = readout.transpose();
  const Eigen::Index shown = h.cols() - out.temperatures;
  if (shown > 0) {
    // Displacement rows act on T - T_ref: subtract T_ref times the rows' response to 1 K.
    const Eigen::VectorXd per_kelvin = out.rows.bottomRows(shown) * uniform;
    h.rightCols(shown).rowwise() -= (out.reference_k * per_kelvin).transpose();
  }
  return h;
}

Twin build_twin(const FullThermalSystem& full, const core::CaseSpec& spec,
                const TwinOutputs& outputs, const ReductionOptions& options) {
  Twin twin;
  twin.model = reduced_model(full, spec, options);
  twin.outputs = projected_outputs(outputs, twin.model.basis);
  return twin;
}

Twin case_twin(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
               const ReductionOptions& options) {
  return case_twin(mesh, spec, thermal_system(mesh, spec), options);
}

Twin case_twin(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const FullThermalSystem& full,
               const ReductionOptions& options) {
  // The displacement outputs (the stiffness factor and its block adjoint solve) and the thermal
  // basis (a factor per film state and shift) are independent: they are built side by side.
  TwinOutputs outputs;
  Twin twin;
  core::parallel_invoke(
      [&] {
        if (spec.mechanical.enabled && !spec.mechanical.tcp_point.empty()) {
          const ElasticModel elastic(mesh, spec);
          outputs = full_outputs(mesh, spec, &elastic);
        } else {
          outputs = full_outputs(mesh, spec, nullptr);
        }
      },
      [&] { twin.model = reduced_model(full, spec, options); });
  twin.outputs = projected_outputs(outputs, twin.model.basis);
  return twin;
}

TwinRun twin_run(const Twin& twin, const core::CaseSpec& spec, const Progress& progress) {
  StepperRequest request;
  request.record_times = output_times(spec);
  request.record_states = true;
  const SteppedHistory h = step_thermal(twin.model.system, spec, request, progress);
  TwinRun run;
  run.times = h.times;
  run.states = h.states;
  run.outputs =
      output_history(twin.outputs, twin.outputs.rows * h.states, twin.model.system.uniform);
  run.timings = h.timings;
  run.heat_in = h.heat_in;
  run.lost = h.lost;
  return run;
}

ErrorIndicator twin_indicator(const FullThermalSystem& full, const ReducedModel& model,
                              const core::CaseSpec& spec, int samples) {
  if (spec.thermal.scheme != core::TimeScheme::backward_euler)
    throw core::SolverError(
        "the reduced model's error indicator samples backward-Euler steps; "
        "this case uses another scheme: check it with run --rom --verify");
  const std::vector<double> grid = time_grid(spec, spec.thermal.step);
  const std::vector<double> outs = output_times(spec);
  const std::vector<double> switches = switch_times(spec);
  // The grid steps that end at an output time, thinned to `samples` spread evenly.
  std::vector<std::size_t> ends;
  for (std::size_t i = 0, j = 0; i < grid.size() && j < outs.size(); ++i) {
    while (j < outs.size() && outs[j] < grid[i]) ++j;
    if (j < outs.size() && outs[j] == grid[i]) ends.push_back(i);
  }
  std::vector<std::size_t> chosen;
  const std::size_t n = ends.size(), k = std::min<std::size_t>(n, std::max(1, samples));
  for (std::size_t m = 0; m < k; ++m) chosen.push_back(ends[n - 1 - m * n / k]);
  std::sort(chosen.begin(), chosen.end());
  chosen.erase(std::unique(chosen.begin(), chosen.end()), chosen.end());
  StepperRequest request;
  for (std::size_t i : chosen) {
    if (i > 0) request.record_times.push_back(grid[i - 1]);
    request.record_times.push_back(grid[i]);
  }
  std::sort(request.record_times.begin(), request.record_times.end());
  request.record_times.erase(std::unique(request.record_times.begin(), request.record_times.end()),
                             request.record_times.end());
  const SteppedHistory h = step_thermal(model.system, spec, request);
  const auto state_at = [&](double t) -> Eigen::VectorXd {
    const auto it = std::find(h.times.begin(), h.times.end(), t);
    return h.states.col(it - h.times.begin());
  };
  std::vector<ReducedStep> steps;
  for (std::size_t i : chosen) {
    ReducedStep s;
    const double t0 = i > 0 ? grid[i - 1] : 0.0, t1 = grid[i];
    s.dt = t1 - t0;
    s.state_old = state_at(t0);
    s.state_new = state_at(t1);
    StepLoad load = step_load(full, spec, t0, t1, model.basis * s.state_old);
    s.load = std::move(load.load);
    s.film = std::move(load.film);
    double last_switch = 0;
    for (double w : switches)
      if (w < t1) last_switch = w;
    s.horizon = t1 - last_switch;
    steps.push_back(std::move(s));
  }
  return error_indicator(full, model, steps);
}

Eigen::MatrixXd full_outputs_history(const FullThermalSystem& full, const TwinOutputs& outputs,
                                     const core::CaseSpec& spec, const Progress& progress) {
  StepperRequest request;
  request.record_times = output_times(spec);
  request.record_states = false;
  request.base_readout.dense = outputs.rows;
  const SteppedHistory h = step_thermal(full, spec, request, progress);
  return output_history(outputs, h.readout, full.uniform);
}

bool TwinComparison::passes(double temperature_limit_k) const {
  return max_temperature_error_k <= temperature_limit_k &&
         (drift_error_m.array() <= drift_limit_m.array()).all();
}

TwinComparison compare_outputs(const TwinOutputs& out, const Eigen::MatrixXd& full,
                               const Eigen::MatrixXd& reduced) {
  if (full.rows() != reduced.rows() || full.cols() != reduced.cols())
    throw core::SolverError("full and reduced histories differ in shape (" +
                            std::to_string(full.rows()) + " x " + std::to_string(full.cols()) +
                            " and " + std::to_string(reduced.rows()) + " x " +
                            std::to_string(reduced.cols()) + ")");
  TwinComparison c;
  const Eigen::Index nt = out.temperatures;
  if (nt > 0) {
    const Eigen::MatrixXd dt = (full.leftCols(nt) - reduced.leftCols(nt)).cwiseAbs();
    Eigen::Index row = 0, col = 0;
    c.max_temperature_error_k = dt.maxCoeff(&row, &col);
    c.worst_point = out.names[static_cast<std::size_t>(col)];
  }
  const Eigen::MatrixXd df = drift_columns(out, full), dr = drift_columns(out, reduced);
  const Eigen::Index nd = df.cols();
  c.drift_error_m = (df - dr).cwiseAbs().colwise().maxCoeff().transpose();
  c.drift_peak_m = df.cwiseAbs().colwise().maxCoeff().transpose();
  c.drift_limit_m = (0.01 * c.drift_peak_m).cwiseMax(0.02e-6);
  for (Eigen::Index k = 0; k < nd; ++k) {
    const Eigen::Index row = out.tcp && k < 3 ? out.temperatures + k : full.cols() - nd + k;
    c.drift_names.push_back(out.names[static_cast<std::size_t>(row)]);
  }
  return c;
}

namespace {

void require_tcp_rows(const TwinOutputs& out) {
  if (!out.tcp)
    throw core::SolverError(
        "the model has no TCP rows: a campaign needs the thermal error at the tool "
        "(mechanical.enabled and mechanical.tcp_point in the case it was built from)");
}

}  // namespace

CampaignResult campaign_result(const TwinOutputs& out, const CampaignRun& run,
                               const std::vector<double>& times, const Eigen::MatrixXd& history,
                               Eigen::MatrixXd node_temperature) {
  require_tcp_rows(out);
  CampaignResult c{run.name, run.shape, times, {}, std::move(node_temperature), {}, {}};
  c.point_temperature = history.leftCols(out.temperatures);
  c.error =
      thermal_error_of(history.middleCols(out.temperatures, 9).transpose(), out.probe_distance)
          .values;
  const auto& ids = run.spec.mechanical.axis_points;
  Eigen::MatrixXd axis(history.rows(), 3 * static_cast<Eigen::Index>(ids.size()));
  for (std::size_t i = 0; i < ids.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      const std::string name = ids[i] + "_d" + kAxes[d];
      const auto at = std::find(out.names.begin(), out.names.end(), name);
      if (at == out.names.end())
        throw core::SolverError("the model has no output '" + name + "' for axis point '" + ids[i] +
                                "'; hint: build the reduced model again from a case that names it "
                                "in mechanical.axis_points");
      axis.col(static_cast<Eigen::Index>(3 * i) + d) = history.col(at - out.names.begin());
    }
  c.axis = axis_error_at_points(run.spec, axis);
  return c;
}

std::vector<CampaignResult> twin_campaign(const Twin& twin, const std::vector<CampaignRun>& runs,
                                          const Progress& progress,
                                          const std::vector<int>& sampled_nodes) {
  require_tcp_rows(twin.outputs);
  Eigen::MatrixXd node_rows(static_cast<Eigen::Index>(sampled_nodes.size()), twin.model.states());
  for (std::size_t i = 0; i < sampled_nodes.size(); ++i) {
    if (sampled_nodes[i] < 0 || sampled_nodes[i] >= twin.model.basis.rows())
      throw core::SolverError("node " + std::to_string(sampled_nodes[i]) +
                              " asked for a history: the " + "reduced model has " +
                              std::to_string(twin.model.basis.rows()) + " nodes");
    node_rows.row(static_cast<Eigen::Index>(i)) = twin.model.basis.row(sampled_nodes[i]);
  }
  double total = 0, done = 0;
  for (const auto& r : runs) total += r.spec.duty_cycle.end;
  std::vector<CampaignResult> results;
  for (const auto& r : runs) {
    const TwinRun run = twin_run(twin, r.spec, [&](double t, double) {
      if (progress) progress(done + t, total);
    });
    done += r.spec.duty_cycle.end;
    results.push_back(campaign_result(twin.outputs, r, run.times, run.outputs,
                                      (node_rows * run.states).transpose()));
  }
  return results;
}

std::vector<TwinComparison> validate_twin(const FullThermalSystem& full,
                                          const TwinOutputs& full_out, const Twin& twin,
                                          const std::vector<CampaignRun>& runs,
                                          const Progress& progress) {
  double total = 0, done = 0;
  for (const auto& r : runs) total += r.spec.duty_cycle.end;
  std::vector<TwinComparison> out;
  for (const auto& r : runs) {
    const Eigen::MatrixXd f = full_outputs_history(full, full_out, r.spec, [&](double t, double) {
      if (progress) progress(done + t, total);
    });
    done += r.spec.duty_cycle.end;
    const TwinRun reduced = twin_run(twin, r.spec);
    TwinComparison c = compare_outputs(full_out, f, reduced.outputs);
    c.run = r.name;
    c.shape = r.shape;
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace tt::solvers
