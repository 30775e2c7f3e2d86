// thermotwin: the command-line driver.
//   thermotwin mesh CASE --out DIR   mesh a case: mesh.vtu, boundary.vtp, points.vtp, mesh_report.json
//   thermotwin run CASE --out DIR    simulate it: fields.pvd, temperatures.csv, thermal_error.csv, summary.json
// Errors print one line on stderr and exit non-zero; no partial output directory is left.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdlib>
#include <iostream>

#include "app/commands.hpp"
#include "core/errors.hpp"
#include "solvers/cholmod/cholmod_factor.hpp"

int main(int argc, char** argv) {
  using namespace tt::app;
  CLI::App cli{"thermotwin: thermal twin of a machine tool"};
  cli.require_subcommand(1);

  MeshArgs mesh_args;
  auto* mesh = cli.add_subcommand("mesh", "Mesh a case and write the mesh, its boundary and named points");
  mesh->add_option("case", mesh_args.case_file, "case file (TOML)")->required()->check(CLI::ExistingFile);
  mesh->add_option("--out", mesh_args.out, "output directory")->required();

  RunArgs run_args;
  auto* run = cli.add_subcommand("run", "Simulate a case: heat transfer, thermo-elasticity, thermal error");
  run->add_option("case", run_args.case_file, "case file (TOML)")->required()->check(CLI::ExistingFile);
  run->add_option("--out", run_args.out, "output directory")->required();
  run->add_flag("--quiet", run_args.quiet, "no progress on stderr");

  CLI11_PARSE(cli, argc, argv);
  // BLAS threads: TT_BLAS_THREADS, default 1 (see set_blas_threads).
  const char* blas = std::getenv("TT_BLAS_THREADS");
  tt::solvers::cholmod::set_blas_threads(blas ? std::max(1, std::atoi(blas)) : 1);
  try {
    if (*mesh) return mesh_command(mesh_args);
    if (*run) return run_command(run_args);
  } catch (const tt::core::Error& e) {
    std::cerr << "thermotwin: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "thermotwin: unexpected error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
