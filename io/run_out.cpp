#include "io/run_out.hpp"

#include <cstdint>

#include "core/timing.hpp"
#include "core/units.hpp"
#include "io/atomic_dir.hpp"
#include "io/axis_out.hpp"
#include "io/candidates_csv.hpp"
#include "io/case_reader.hpp"
#include "io/csv_out.hpp"
#include "io/plot.hpp"
#include "io/reports.hpp"
#include "io/vtk_out.hpp"
#include "mesh/mesher.hpp"
#include "solvers/loads.hpp"

namespace tt::io {

using core::seconds_since;
namespace {

/// temperatures.csv: time_s, then <id>_degC per named point.
void write_temperatures(const mesh::TetMesh& mesh, const solvers::ThermalHistory& th,
                        const std::filesystem::path& path) {
  std::vector<std::string> header{"time_s"};
  for (const auto& p : mesh.points) header.push_back(p.id + "_degC");
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(th.times.size()),
                       static_cast<Eigen::Index>(header.size()));
  for (size_t t = 0; t < th.times.size(); ++t) {
    rows(t, 0) = th.times[t];
    for (size_t i = 0; i < mesh.points.size(); ++i)
      rows(t, i + 1) = th.temperature(mesh.points[i].node, t) - core::kCelsiusOffset;
  }
  write_csv(path, header, rows);
}

/// candidates.csv and candidate_temperatures.csv (time_s, then <id>_degC per candidate): the
/// histories `place --from` chooses sensors from when the case asks for surface candidates.
void write_candidates(const studies::CandidateSet& set, const solvers::ThermalHistory& th,
                      const std::filesystem::path& dir) {
  write_candidates_csv(dir / kCandidatesCsv, {set.names, set.nodes, set.positions});
  std::vector<std::string> header{"time_s"};
  for (const auto& id : set.names) header.push_back(id + "_degC");
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(th.times.size()),
                       static_cast<Eigen::Index>(header.size()));
  rows.col(0) = Eigen::Map<const Eigen::VectorXd>(th.times.data(), rows.rows());
  rows.rightCols(rows.cols() - 1) =
      solvers::nodal_history(th, set.nodes).array() - core::kCelsiusOffset;
  write_csv(dir / kCandidateTemperaturesCsv, header, rows);
}

/// thermal_error.csv: the TCP and probe columns, then the feed axis's points when there are any.
void write_thermal_error(const solvers::ThermalHistory& th, const solvers::ThermalError& e,
                         const solvers::AxisError* axis, const std::filesystem::path& path) {
  std::vector<std::string> header{"time_s",
                                  "dx_um",
                                  "dy_um",
                                  "dz_um",
                                  "dx_z1_um",
                                  "dy_z1_um",
                                  "dx_z2_um",
                                  "dy_z2_um",
                                  "tilt_about_x_urad",
                                  "tilt_about_y_urad"};
  const Eigen::Index extra = axis ? axis->values.cols() : 0;
  Eigen::MatrixXd rows(e.values.rows(), 10 + extra);
  for (Eigen::Index t = 0; t < e.values.rows(); ++t) {
    rows(t, 0) = th.times[t];
    rows.row(t).segment(1, 9) = e.values.row(t) * 1e6;  // m -> um, rad -> urad
  }
  if (axis) {
    const auto names = axis_error_header(*axis);
    header.insert(header.end(), names.begin(), names.end());
    rows.rightCols(extra) = axis_error_rows_um(*axis);
  }
  write_csv(path, header, rows);
}

void write_fields(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                  const solvers::VirtualRun& run, const std::filesystem::path& dir) {
  FieldSeriesWriter writer(mesh, dir, "fields");
  const auto& th = run.thermal;
  const double t0_k = spec.thermal.initial_temperature_c + core::kCelsiusOffset;
  double next = 0;
  for (size_t t = 0; t < th.times.size(); ++t) {
    const bool last = t + 1 == th.times.size();
    if (th.times[t] + 1e-9 < next && !last) continue;
    next = th.times[t] + spec.outputs.fields_interval;
    const Eigen::VectorXd temp = th.temperature.col(static_cast<Eigen::Index>(t));
    std::vector<NamedField> point{{"temperature_degC", 1, temp.array() - core::kCelsiusOffset},
                                  {"temperature_rise_K", 1, temp.array() - t0_k}};
    if (run.elastic) {
      const Eigen::VectorXd u = run.elastic->displacement.col(static_cast<Eigen::Index>(t));
      point.push_back({"displacement_m", 3, u});
      point.push_back({"von_mises_Pa", 1, solvers::von_mises_nodal(mesh, spec, u, temp)});
    }
    writer.add_step(th.times[t], point);
  }
  writer.finish();
}

/// summary.json's "model": which thermal model ran, and for a reduced one its order, source, its
/// error indicator and the full-order check when --verify asked for it.
nlohmann::json model_json(const RunModel& model, const studies::VirtualRunReport& r) {
  if (!model.reduced) return {{"kind", "full"}};
  nlohmann::json j{{"kind", "reduced"},
                   {"order", model.order},
                   {"rom", std::filesystem::absolute(model.rom).string()},
                   {"built_from", model.built_from}};
  if (r.check) {
    const auto& check = *r.check;
    j["verify"] = {
        {"max_temperature_error_K", check.max_temperature_error_k},
        {"max_point_temperature_error_K", check.max_point_error_k},
        {"tcp_error_um",
         {check.tcp_error_m(0) * 1e6, check.tcp_error_m(1) * 1e6, check.tcp_error_m(2) * 1e6}},
        {"tcp_peak_um",
         {check.tcp_peak_m(0) * 1e6, check.tcp_peak_m(1) * 1e6, check.tcp_peak_m(2) * 1e6}},
        {"full_s", check.full_s}};
  }
  if (r.indicator)
    j["indicator"] = {{"max_K", r.indicator->max_k},
                      {"samples_K", r.indicator->samples_k},
                      {"tolerance_K", r.indicator->tolerance_k},
                      {"above_tolerance", r.indicator->above_tolerance()}};
  else
    j["indicator"] = "not computed for this scheme (backward Euler only): see verify";
  return j;
}

nlohmann::json summary_json(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                            const studies::VirtualRunReport& r, const RunModel& model,
                            double mesh_s, double write_s) {
  const auto& run = r.run;
  const auto& e = run.thermal.energy;
  nlohmann::json summary;
  summary["case"] = spec.name;
  summary["nodes"] = mesh.nodes.rows();
  summary["tets"] = mesh.tets.rows();
  summary["order"] = mesh.order;
  summary["thermal_dofs"] = mesh.nodes.rows();
  summary["model"] = model_json(model, r);
  summary["steps"] = run.thermal.timings.steps;
  summary["factorizations"] = run.thermal.timings.factorizations;
  summary["peak_temperature_degC"] = run.thermal.temperature.maxCoeff() - core::kCelsiusOffset;
  summary["energy_balance"] = {{"heat_in_J", e.heat_in},
                               {"heat_in_from_laws_J", e.heat_in_law},
                               {"stored_J", e.stored},
                               {"lost_J", e.lost},
                               {"closure_rel", e.closure()}};
  nlohmann::json timings{{"mesh_s", mesh_s},
                         {"thermal_assemble_s", run.thermal.timings.assemble_s},
                         {"thermal_factor_s", run.thermal.timings.factor_s},
                         {"thermal_solve_s", run.thermal.timings.solve_s},
                         {"simulate_s", r.simulate_s},
                         {"write_s", write_s}};
  if (run.elastic) {
    summary["elastic_dofs"] = run.elastic->timings.dofs;
    timings["elastic_assemble_s"] = run.elastic->timings.assemble_s;
    timings["elastic_factor_s"] = run.elastic->timings.factor_s;
    timings["elastic_solve_s"] = run.elastic->timings.solve_s;
  }
  if (run.error) {
    const auto last = run.error->values.bottomRows(1);
    summary["thermal_error_at_end_um"] = {
        {"dx", last(0, 0) * 1e6}, {"dy", last(0, 1) * 1e6}, {"dz", last(0, 2) * 1e6}};
  }
  if (r.axis) summary["feed_axis_error"] = axis_summary_json(*r.axis, *r.axis_polynomial);
  summary["timings"] = timings;
  return summary;
}

/// Patent figures 3 and 4, when matplotlib is there.
void plot_run(const std::filesystem::path& dir, const core::CaseSpec& spec, bool has_error) {
  if (!spec.outputs.plot_points.empty()) {
    std::string cols;
    for (const auto& id : spec.outputs.plot_points)
      cols += (cols.empty() ? "" : ",") + id + "_degC";
    plot({"temperatures", (dir / "temperatures.csv").string(),
          (dir / "temperature_rise.png").string(), "--columns=" + cols, "--rise-from-first",
          "--title=" + spec.name + ": temperature rise"});
  }
  if (has_error)
    plot({"thermal_error", (dir / "thermal_error.csv").string(),
          (dir / "thermal_error.png").string(), "--columns=dx_um,dy_um,dz_um",
          "--title=" + spec.name + ": thermal error at the TCP"});
}

}  // namespace

void write_mesh_files(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                      const std::filesystem::path& dir) {
  write_mesh_vtu(mesh, dir / "mesh.vtu");
  write_boundary_vtp(mesh, dir / "boundary.vtp");
  write_points_vtp(mesh, dir / "points.vtp");
  write_json(dir / "mesh_report.json", mesh_report_json(mesh, mesh::mesh_report(mesh, spec)));
  write_file_atomically(dir / "case.resolved.toml", resolved_case_toml(spec));
}

void write_dump(const solvers::VirtualRun& run, const std::filesystem::path& path) {
  std::string bytes;
  const auto put_matrix = [&](const Eigen::MatrixXd& m) {
    const std::int64_t shape[2] = {m.rows(), m.cols()};
    bytes.append(reinterpret_cast<const char*>(shape), sizeof shape);
    bytes.append(reinterpret_cast<const char*>(m.data()),
                 static_cast<size_t>(m.size()) * sizeof(double));
  };
  put_matrix(run.thermal.temperature);
  if (run.elastic) put_matrix(run.elastic->displacement);
  write_file_atomically(path, bytes);
}

void write_run(const std::filesystem::path& dir, const mesh::TetMesh& mesh,
               const core::CaseSpec& spec, const studies::VirtualRunReport& report,
               const RunModel& model, double mesh_s,
               std::chrono::steady_clock::time_point started) {
  const auto& run = report.run;
  const auto t_write = std::chrono::steady_clock::now();
  write_mesh_files(mesh, spec, dir);
  write_temperatures(mesh, run.thermal, dir / "temperatures.csv");
  if (report.candidates) write_candidates(*report.candidates, run.thermal, dir);
  if (report.axis)
    write_axis_polynomial_csv(dir / "axis_polynomial.csv", run.thermal.times,
                              *report.axis_polynomial);
  if (run.error)
    write_thermal_error(run.thermal, *run.error, report.axis ? &*report.axis : nullptr,
                        dir / "thermal_error.csv");
  if (spec.outputs.fields) write_fields(mesh, spec, run, dir);
  nlohmann::json summary = summary_json(mesh, spec, report, model, mesh_s, seconds_since(t_write));
  summary["timings"]["total_s"] = seconds_since(started);
  write_json(dir / "summary.json", summary);
  plot_run(dir, spec, run.error.has_value());
}

}  // namespace tt::io
