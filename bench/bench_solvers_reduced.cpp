// Benchmark: the reduced-order twin against the full model on one case (default cases/sb1.toml).
//   build/bench_solvers_reduced [CASE] [--repeats N]
// Meshes the case, assembles the full system, builds the twin (influence rows, basis, projection)
// and steps the case's own duty cycle (P-1 on SB-1: 2 h at 12 s steps) in full and reduced order
// in the same process. Prints the mesh size, the reduced order, the build time and peak memory,
// the stepping time of both and their ratio, and the largest differences at the outputs.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>

#include "core/timing.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/twin.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using tt::core::seconds_since;

/// Peak resident set of this process so far [MB] (VmHWM).
double peak_rss_mb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tt;
  std::string case_file = TT_SOURCE_DIR "/cases/sb1.toml";
  int repeats = 20;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--repeats") == 0 && i + 1 < argc)
      repeats = std::max(1, std::atoi(argv[++i]));
    else
      case_file = argv[i];
  }
  try {
    const core::CaseSpec spec = io::read_case(case_file);
    auto t = Clock::now();
    const mesh::TetMesh mesh = mesh::mesh_case(spec);
    const double mesh_s = seconds_since(t);
    t = Clock::now();
    const solvers::FullThermalSystem full = solvers::thermal_system(mesh, spec);
    const double assemble_s = seconds_since(t);
    t = Clock::now();
    std::optional<solvers::ElasticModel> elastic;
    if (spec.mechanical.enabled && !spec.mechanical.tcp_point.empty()) elastic.emplace(mesh, spec);
    const solvers::TwinOutputs out =
        solvers::full_outputs(mesh, spec, elastic ? &*elastic : nullptr);
    elastic.reset();
    const double outputs_s = seconds_since(t);
    t = Clock::now();
    const solvers::Twin twin = solvers::build_twin(full, spec, out);
    const double reduce_s = seconds_since(t);
    const double build_rss = peak_rss_mb();

    t = Clock::now();
    const Eigen::MatrixXd f = solvers::full_outputs_history(full, out, spec);
    const double full_s = seconds_since(t);
    double reduced_s = 1e300;
    solvers::TwinRun run;
    for (int k = 0; k < repeats; ++k) {
      t = Clock::now();
      run = solvers::twin_run(twin, spec);
      reduced_s = std::min(reduced_s, seconds_since(t));
    }
    const solvers::TwinComparison c = solvers::compare_outputs(out, f, run.outputs);

    std::printf("case %s: %ld nodes, %ld tets, order %d\n", case_file.c_str(),
                static_cast<long>(mesh.nodes.rows()), static_cast<long>(mesh.tets.rows()),
                mesh.order);
    std::printf(
        "mesh %.1f s, assemble %.1f s, influence rows %.1f s, reduce %.1f s (%d factors, "
        "%d of %d columns kept)\n",
        mesh_s, assemble_s, outputs_s, reduce_s, twin.model.stats.factorizations,
        twin.model.states(), twin.model.stats.candidate_columns);
    std::printf("reduced order r = %d; peak RSS after the build %.0f MB\n", twin.model.states(),
                build_rss);
    std::printf(
        "duty cycle %.0f s, %d steps: full %.3f s, reduced %.6f s (best of %d), ratio "
        "%.0f, %.3g x real time\n",
        spec.duty_cycle.end, run.timings.steps, full_s, reduced_s, repeats, full_s / reduced_s,
        spec.duty_cycle.end / reduced_s);
    std::printf("max |dT| %.2e K (%s)", c.max_temperature_error_k, c.worst_point.c_str());
    for (std::size_t k = 0; k < c.drift_names.size(); ++k) {
      const auto i = static_cast<Eigen::Index>(k);
      std::printf("; %s %.4f um of peak %.3f um", c.drift_names[k].c_str(),
                  c.drift_error_m(i) * 1e6, c.drift_peak_m(i) * 1e6);
    }
    std::printf("\n%s\n", c.passes() ? "within limits" : "OUTSIDE limits");
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_solvers_reduced: " << e.what() << "\n";
    return 1;
  }
}
