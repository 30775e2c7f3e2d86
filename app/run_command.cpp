// thermotwin mesh / run: the virtual machine's drivers.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>

#include "app/commands.hpp"
#include "core/errors.hpp"
#include "core/timing.hpp"
#include "io/atomic_dir.hpp"
#include "io/case_reader.hpp"
#include "io/checkpoint.hpp"
#include "io/reduced_model_io.hpp"
#include "io/run_out.hpp"
#include "mesh/mesher.hpp"
#include "studies/virtual_run.hpp"

namespace tt::app {

using core::seconds_since;
namespace {

using Clock = std::chrono::steady_clock;
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
  io::write_mesh_files(mesh, spec, out.path());
  out.commit();
  std::cerr << "thermotwin: mesh: " << mesh.nodes.rows() << " nodes, " << mesh.tets.rows()
            << " tets -> " << args.out.string() << "\n";
  return 0;
}

namespace {

/// The case, with the duty cycle of --duty-cycle when given.
core::CaseSpec run_case(const RunArgs& args) {
  if (args.end_s && args.duty_cycle.empty())
    throw core::CaseError("run: --end-s " + std::to_string(*args.end_s) +
                          " sets the end of a duty cycle given with --duty-cycle; hint: give "
                          "--duty-cycle FILE.csv, or change duty_cycle.end_s in the case");
  return args.duty_cycle.empty()
             ? io::read_case(args.case_file)
             : io::with_duty_cycle_csv(io::read_case(args.case_file), args.duty_cycle, args.end_s);
}

/// The reduced model of --rom, checked to have been built for this machine and mesh.
std::optional<io::ReducedModelFile> run_rom(const RunArgs& args, const core::CaseSpec& spec,
                                            const mesh::TetMesh& mesh) {
  if (args.rom.empty()) {
    if (args.verify)
      throw core::CaseError(
          "run: --verify compares a reduced run with the full model: give --rom DIR");
    return std::nullopt;
  }
  if (args.resume)
    throw core::CaseError("run: --resume continues a full run; a run with --rom " +
                          args.rom.string() + " takes seconds: run it again without --resume");
  io::ReducedModelFile rom = io::read_reduced_model(args.rom);
  io::check_reduced_model_fits(rom, io::reduced_model_key(spec, mesh), args.rom);
  return rom;
}

/// The time loop saves its state beside DIR (DIR.checkpoint) so that --resume continues a run that
/// was killed; a save that fails (disk full) costs only the resume point: warned once, the run goes
/// on. `resumed` holds the state read back with --resume.
solvers::Checkpointing run_checkpointing(const RunArgs& args, const std::filesystem::path& file,
                                         const io::CheckpointKey& key,
                                         std::optional<solvers::ThermalCheckpoint>& resumed) {
  if (args.resume && std::filesystem::exists(file)) {
    resumed = io::read_checkpoint(file, key);
    std::cerr << "thermotwin: resuming at t = " << resumed->time << " s (step " << resumed->steps
              << ")\n";
  } else if (args.resume) {
    std::cerr << "thermotwin: note: no checkpoint at " << file.string() << "; starting at t = 0\n";
  }
  solvers::Checkpointing checkpointing;
  checkpointing.interval_s = args.stop_after_steps > 0 ? 0 : args.checkpoint_every_s;
  checkpointing.resume = resumed ? &*resumed : nullptr;
  if (args.stop_after_steps > 0 || args.checkpoint_every_s >= 0)
    checkpointing.save =
        [file, key, stop = args.stop_after_steps,
         failed = std::make_shared<bool>(false)](const solvers::ThermalCheckpoint& state) {
          try {
            io::write_checkpoint(file, key, state);
          } catch (const core::IoError& e) {
            if (!*failed)
              std::cerr << "thermotwin: warning: checkpoint not saved: " << e.what()
                        << "; the run goes on (--resume would start from an earlier state)\n";
            *failed = true;
          }
          if (stop > 0 && state.steps >= stop) std::_Exit(3);  // as if killed
        };
  return checkpointing;
}

/// The case's mesh; its size and time on stderr unless quiet.
mesh::TetMesh meshed(const core::CaseSpec& spec, bool quiet, double& mesh_s) {
  const auto t_mesh = Clock::now();
  mesh::TetMesh mesh = mesh::mesh_case(spec);
  mesh_s = seconds_since(t_mesh);
  if (!quiet)
    std::cerr << "thermotwin: mesh: " << mesh.nodes.rows() << " nodes, " << mesh.tets.rows()
              << " tets (" << mesh_s << " s)\n";
  return mesh;
}

/// The reduced model's error indicator above its tolerance: say so, with what to do.
void warn_if_indicator_above_tolerance(const studies::VirtualRunReport& report) {
  if (report.indicator && report.indicator->above_tolerance())
    std::cerr << "thermotwin: warning: the reduced model's error indicator is "
              << report.indicator->max_k << " K, above its tolerance of "
              << report.indicator->tolerance_k
              << " K: check with --verify, or rebuild the model (reduce) for this duty cycle\n";
}

}  // namespace

int run_command(const RunArgs& args) {
  const auto t_start = Clock::now();
  // 1. Read and validate the case; claim the output and the checkpoint beside it before any
  //    work, so that a refused or unwritable --out fails at once, not after the solve.
  const core::CaseSpec spec = run_case(args);
  const std::filesystem::path checkpoint = io::checkpoint_path(args.out);
  std::vector<std::filesystem::path> inputs = io::case_input_files(spec);
  inputs.push_back(checkpoint);
  if (!args.rom.empty()) inputs.push_back(args.rom);
  io::OutputDir out(args.out, inputs);
  if (args.stop_after_steps > 0 || args.checkpoint_every_s >= 0)
    io::require_writable_checkpoint(checkpoint);
  // 2. Mesh; the reduced model, when given.
  double mesh_s = 0;
  const mesh::TetMesh mesh = meshed(spec, args.quiet, mesh_s);
  const auto say = [&](const std::string& line) {
    if (!args.quiet) std::cerr << "thermotwin: " << line << "\n";
  };
  const std::optional<io::ReducedModelFile> rom = run_rom(args, spec, mesh);
  // 3. Simulate: heat transfer, then thermo-elasticity.
  std::optional<solvers::ThermalCheckpoint> resumed;
  const solvers::Checkpointing checkpointing =
      run_checkpointing(args, checkpoint, io::checkpoint_key(spec, mesh), resumed);
  const solvers::Progress progress = [&](double t, double end) {
    if (!args.quiet) report_progress(rom ? "thermal (reduced)" : "thermal", t, end);
  };
  const studies::VirtualRunReport report = studies::virtual_run(
      mesh, spec, {rom ? &rom->twin : nullptr, args.verify, progress, say, checkpointing});
  warn_if_indicator_above_tolerance(report);
  if (!args.dump.empty()) io::write_dump(report.run, args.dump);
  // 4. Write everything into DIR.partial, then publish it as DIR.
  io::RunModel model;
  if (rom) model = {true, static_cast<long>(rom->twin.model.states()), args.rom, rom->case_name};
  io::write_run(out.path(), mesh, spec, report, model, mesh_s, t_start);
  out.commit();
  std::error_code no_checkpoint;
  std::filesystem::remove(checkpoint, no_checkpoint);
  std::cerr << "thermotwin: run: done in " << seconds_since(t_start) << " s -> "
            << args.out.string() << "\n";
  return 0;
}

}  // namespace tt::app
