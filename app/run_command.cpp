// thermotwin mesh / run: the virtual machine's drivers.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <optional>

#include "app/commands.hpp"
#include "app/study.hpp"
#include "core/errors.hpp"
#include "core/units.hpp"
#include "io/atomic_dir.hpp"
#include "io/axis_out.hpp"
#include "io/candidates_csv.hpp"
#include "io/case_reader.hpp"
#include "io/checkpoint.hpp"
#include "io/csv_out.hpp"
#include "io/reduced_model_io.hpp"
#include "io/reports.hpp"
#include "io/vtk_out.hpp"
#include "mesh/mesher.hpp"
#include "solvers/axis_error.hpp"
#include "solvers/loads.hpp"
#include "solvers/virtual_machine.hpp"

namespace tt::app {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void write_mesh_files(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                      const std::filesystem::path& dir) {
  io::write_mesh_vtu(mesh, dir / "mesh.vtu");
  io::write_boundary_vtp(mesh, dir / "boundary.vtp");
  io::write_points_vtp(mesh, dir / "points.vtp");
  io::write_json(dir / "mesh_report.json",
                 io::mesh_report_json(mesh, mesh::mesh_report(mesh, spec)));
  io::write_file_atomically(dir / "case.resolved.toml", io::resolved_case_toml(spec));
}

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
  io::write_csv(path, header, rows);
}

/// candidates.csv and candidate_temperatures.csv (time_s, then <id>_degC per candidate): the
/// histories `place --from` chooses sensors from when the case asks for surface candidates.
void write_candidates(const CandidateSet& set, const solvers::ThermalHistory& th,
                      const std::filesystem::path& dir) {
  io::write_candidates_csv(dir / io::kCandidatesCsv, {set.names, set.nodes, set.positions});
  std::vector<std::string> header{"time_s"};
  for (const auto& id : set.names) header.push_back(id + "_degC");
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(th.times.size()),
                       static_cast<Eigen::Index>(header.size()));
  rows.col(0) = Eigen::Map<const Eigen::VectorXd>(th.times.data(), rows.rows());
  rows.rightCols(rows.cols() - 1) =
      solvers::nodal_history(th, set.nodes).array() - core::kCelsiusOffset;
  io::write_csv(dir / io::kCandidateTemperaturesCsv, header, rows);
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
    const auto names = io::axis_error_header(*axis);
    header.insert(header.end(), names.begin(), names.end());
    rows.rightCols(extra) = io::axis_error_rows_um(*axis);
  }
  io::write_csv(path, header, rows);
}

void write_fields(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                  const solvers::VirtualRun& run, const std::filesystem::path& dir) {
  io::FieldSeriesWriter writer(mesh, dir, "fields");
  const auto& th = run.thermal;
  const double t0_k = spec.thermal.initial_temperature_c + core::kCelsiusOffset;
  double next = 0;
  for (size_t t = 0; t < th.times.size(); ++t) {
    const bool last = t + 1 == th.times.size();
    if (th.times[t] + 1e-9 < next && !last) continue;
    next = th.times[t] + spec.outputs.fields_interval;
    const Eigen::VectorXd temp = th.temperature.col(static_cast<Eigen::Index>(t));
    std::vector<io::NamedField> point{{"temperature_degC", 1, temp.array() - core::kCelsiusOffset},
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

/// --dump: #nodes, #times, temperatures [K], then #dofs, #times, displacements [m] when there
/// are any, as native int64 and doubles: results compared bit for bit by the reliability tests.
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
  io::write_file_atomically(path, bytes);
}

/// summary.json's "model": which thermal model ran, and for a reduced one its order, source and
/// the full-order check when --verify asked for it.
nlohmann::json model_json(const RunArgs& args, const io::ReducedModelFile* rom,
                          const solvers::ReducedCheck* check) {
  if (!rom) return {{"kind", "full"}};
  nlohmann::json j{{"kind", "reduced"},
                   {"order", rom->twin.model.states()},
                   {"rom", std::filesystem::absolute(args.rom).string()},
                   {"built_from", rom->case_name}};
  if (check)
    j["verify"] = {
        {"max_temperature_error_K", check->max_temperature_error_k},
        {"max_point_temperature_error_K", check->max_point_error_k},
        {"tcp_error_um",
         {check->tcp_error_m(0) * 1e6, check->tcp_error_m(1) * 1e6, check->tcp_error_m(2) * 1e6}},
        {"tcp_peak_um",
         {check->tcp_peak_m(0) * 1e6, check->tcp_peak_m(1) * 1e6, check->tcp_peak_m(2) * 1e6}},
        {"full_s", check->full_s}};
  return j;
}

}  // namespace

void report_progress(const std::string& stage, double done, double total) {
  static int last_decile = -1;
  const int decile = static_cast<int>(std::floor(10 * done / total + 1e-9));
  if (decile == last_decile) return;
  last_decile = decile >= 10 ? -1 : decile;
  std::cerr << "thermotwin: " << stage << " " << 10 * decile << " % (t = " << done << " s of "
            << total << " s)\n";
}

int mesh_command(const MeshArgs& args) {
  // 1. Read and validate the case; claim the output (refused at once when it is not ours).
  const core::CaseSpec spec = io::read_case(args.case_file);
  io::OutputDir out(args.out, io::case_input_files(spec));
  // 2. Mesh all bodies into one conforming mesh.
  const mesh::TetMesh mesh = mesh::mesh_case(spec);
  // 3. Write the mesh, its boundary, the named points and the report, all or nothing.
  write_mesh_files(mesh, spec, out.path());
  out.commit();
  std::cerr << "thermotwin: mesh: " << mesh.nodes.rows() << " nodes, " << mesh.tets.rows()
            << " tets -> " << args.out.string() << "\n";
  return 0;
}

int run_command(const RunArgs& args) {
  const auto t_start = Clock::now();
  // 1. Read and validate the case; claim the output and the checkpoint beside it before any
  //    work, so that a refused or unwritable --out fails at once, not after the solve.
  if (args.end_s && args.duty_cycle.empty())
    throw core::CaseError("run: --end-s " + std::to_string(*args.end_s) +
                          " sets the end of a duty cycle given with --duty-cycle; hint: give "
                          "--duty-cycle FILE.csv, or change duty_cycle.end_s in the case");
  const core::CaseSpec spec =
      args.duty_cycle.empty()
          ? io::read_case(args.case_file)
          : io::with_duty_cycle_csv(io::read_case(args.case_file), args.duty_cycle, args.end_s);
  const std::filesystem::path checkpoint = io::checkpoint_path(args.out);
  std::vector<std::filesystem::path> inputs = io::case_input_files(spec);
  inputs.push_back(checkpoint);
  if (!args.rom.empty()) inputs.push_back(args.rom);
  io::OutputDir out(args.out, inputs);
  const bool checkpoints = args.stop_after_steps > 0 || args.checkpoint_every_s >= 0;
  if (checkpoints) io::require_writable_checkpoint(checkpoint);
  // 2. Mesh.
  const auto t_mesh = Clock::now();
  const mesh::TetMesh mesh = mesh::mesh_case(spec);
  const double mesh_s = seconds_since(t_mesh);
  if (!args.quiet)
    std::cerr << "thermotwin: mesh: " << mesh.nodes.rows() << " nodes, " << mesh.tets.rows()
              << " tets (" << mesh_s << " s)\n";
  // A reduced model, when given, must have been built for this machine and mesh.
  std::optional<io::ReducedModelFile> rom;
  if (!args.rom.empty()) {
    if (args.resume)
      throw core::CaseError("run: --resume continues a full run; a run with --rom " +
                            args.rom.string() + " takes seconds: run it again without --resume");
    rom = io::read_reduced_model(args.rom);
    io::check_reduced_model_fits(*rom, io::reduced_model_key(spec, mesh), args.rom);
  } else if (args.verify) {
    throw core::CaseError(
        "run: --verify compares a reduced run with the full model: give --rom DIR");
  }
  // Surface vertices that are candidate sensors: their histories go to candidate_temperatures.csv.
  std::optional<CandidateSet> candidates;
  if (spec.placement.candidates == core::PlacementSpec::Candidates::surface)
    candidates = candidate_set(spec, mesh);
  // 3. Simulate: heat transfer, then thermo-elasticity. The time loop saves its state beside
  //    DIR (DIR.checkpoint) so that --resume continues a run that was killed; a save that fails
  //    (disk full) costs only the resume point: warned once, the run goes on.
  const io::CheckpointKey key = io::checkpoint_key(spec, mesh);
  std::optional<solvers::ThermalCheckpoint> resumed;
  if (args.resume && std::filesystem::exists(checkpoint)) {
    resumed = io::read_checkpoint(checkpoint, key);
    std::cerr << "thermotwin: resuming at t = " << resumed->time << " s (step " << resumed->steps
              << ")\n";
  } else if (args.resume) {
    std::cerr << "thermotwin: note: no checkpoint at " << checkpoint.string()
              << "; starting at t = 0\n";
  }
  solvers::Checkpointing checkpointing;
  checkpointing.interval_s = args.stop_after_steps > 0 ? 0 : args.checkpoint_every_s;
  checkpointing.resume = resumed ? &*resumed : nullptr;
  bool save_failed = false;
  if (checkpoints)
    checkpointing.save = [&](const solvers::ThermalCheckpoint& state) {
      try {
        io::write_checkpoint(checkpoint, key, state);
      } catch (const core::IoError& e) {
        if (!save_failed)
          std::cerr << "thermotwin: warning: checkpoint not saved: " << e.what()
                    << "; the run goes on (--resume would start from an earlier state)\n";
        save_failed = true;
      }
      if (args.stop_after_steps > 0 && state.steps >= args.stop_after_steps)
        std::_Exit(3);  // as if killed
    };
  const auto t_sim = Clock::now();
  const solvers::Progress progress = [&](double t, double end) {
    if (!args.quiet) report_progress(rom ? "thermal (reduced)" : "thermal", t, end);
  };
  const solvers::VirtualRun run = rom ? solvers::simulate_reduced(mesh, spec, rom->twin, progress)
                                      : solvers::simulate(mesh, spec, progress, checkpointing);
  const double sim_s = seconds_since(t_sim);
  // The reduced run's own error indicator: the full-order residual at sampled output steps.
  std::optional<solvers::ErrorIndicator> indicator;
  if (rom && spec.thermal.scheme == core::TimeScheme::backward_euler) {
    indicator = solvers::twin_indicator(run.operators, rom->twin.model, spec);
    if (indicator->above_tolerance())
      std::cerr << "thermotwin: warning: the reduced model's error indicator is "
                << indicator->max_k << " K, above its tolerance of " << indicator->tolerance_k
                << " K: check with --verify, or rebuild the model (reduce) for this duty cycle\n";
  }
  std::optional<solvers::ReducedCheck> check;
  if (args.verify) {
    if (!args.quiet) std::cerr << "thermotwin: --verify: recomputing the output times in full\n";
    check = solvers::verify_reduced(mesh, spec, run);
  }
  if (!args.dump.empty()) write_dump(run, args.dump);
  // 4. Write everything into DIR.partial, then publish it as DIR.
  const auto& dir = out.path();
  const auto t_write = Clock::now();
  write_mesh_files(mesh, spec, dir);
  write_temperatures(mesh, run.thermal, dir / "temperatures.csv");
  if (candidates) write_candidates(*candidates, run.thermal, dir);
  // The feed axis's error at its measurement points, and its compensation polynomial.
  std::optional<solvers::AxisError> axis;
  std::optional<solvers::AxisPolynomial> axis_poly;
  if (run.elastic && !spec.mechanical.axis_points.empty()) {
    axis = solvers::axis_error(mesh, spec, run.elastic->displacement);
    axis_poly = solvers::axis_polynomial(*axis, spec.mechanical.axis_polynomial_degree);
    io::write_axis_polynomial_csv(dir / "axis_polynomial.csv", run.thermal.times, *axis_poly);
  }
  if (run.error)
    write_thermal_error(run.thermal, *run.error, axis ? &*axis : nullptr,
                        dir / "thermal_error.csv");
  if (spec.outputs.fields) write_fields(mesh, spec, run, dir);
  const double write_s = seconds_since(t_write);

  const auto& e = run.thermal.energy;
  nlohmann::json summary;
  summary["case"] = spec.name;
  summary["nodes"] = mesh.nodes.rows();
  summary["tets"] = mesh.tets.rows();
  summary["order"] = mesh.order;
  summary["thermal_dofs"] = mesh.nodes.rows();
  summary["model"] = model_json(args, rom ? &*rom : nullptr, check ? &*check : nullptr);
  if (rom) {
    if (indicator)
      summary["model"]["indicator"] = {{"max_K", indicator->max_k},
                                       {"samples_K", indicator->samples_k},
                                       {"tolerance_K", indicator->tolerance_k},
                                       {"above_tolerance", indicator->above_tolerance()}};
    else
      summary["model"]["indicator"] =
          "not computed for this scheme (backward Euler only): see "
          "verify";
  }
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
                         {"simulate_s", sim_s},
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
  if (axis) summary["feed_axis_error"] = io::axis_summary_json(*axis, *axis_poly);
  timings["total_s"] = seconds_since(t_start);
  summary["timings"] = timings;
  io::write_json(dir / "summary.json", summary);

  // 5. Figures (patent figures 3 and 4), when matplotlib is there.
  if (!spec.outputs.plot_points.empty()) {
    std::string cols;
    for (const auto& id : spec.outputs.plot_points)
      cols += (cols.empty() ? "" : ",") + id + "_degC";
    plot({"temperatures", (dir / "temperatures.csv").string(),
          (dir / "temperature_rise.png").string(), "--columns=" + cols, "--rise-from-first",
          "--title=" + spec.name + ": temperature rise"});
  }
  if (run.error)
    plot({"thermal_error", (dir / "thermal_error.csv").string(),
          (dir / "thermal_error.png").string(), "--columns=dx_um,dy_um,dz_um",
          "--title=" + spec.name + ": thermal error at the TCP"});
  out.commit();
  std::error_code no_checkpoint;
  std::filesystem::remove(checkpoint, no_checkpoint);
  std::cerr << "thermotwin: run: done in " << seconds_since(t_start) << " s -> "
            << args.out.string() << "\n";
  return 0;
}

}  // namespace tt::app
