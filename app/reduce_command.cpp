// thermotwin reduce CASE --out DIR: the case's reduced-order twin (docs/reduced-order.md).
//   1. read the case, claim the output and mesh the case;
//   2. the study (studies/reduce_case.hpp): the full system and its output rows, the reduced basis
//      and the projections, the twin judged against the full model on duty cycles that were not
//      used to build it;
//   3. reduced_model.json / .bin and validation.csv (io/reduce_out.hpp), all or nothing.
#include <chrono>
#include <iostream>

#include "app/commands.hpp"
#include "core/timing.hpp"
#include "io/atomic_dir.hpp"
#include "io/case_reader.hpp"
#include "io/reduce_out.hpp"
#include "mesh/mesher.hpp"
#include "studies/reduce_case.hpp"

namespace tt::app {

int reduce_command(const ReduceArgs& args) {
  const auto t_start = std::chrono::steady_clock::now();
  const auto say = [&](const std::string& what) {
    if (!args.quiet) std::cerr << "thermotwin: reduce: " << what << "\n";
  };
  // 1. Read the case, claim the output (refused at once when it is not ours), mesh.
  const core::CaseSpec spec = io::read_case(args.case_file);
  io::OutputDir out(args.out, io::case_input_files(spec));
  const mesh::TetMesh mesh = mesh::mesh_case(spec);
  say(std::to_string(mesh.nodes.rows()) + " nodes, " + std::to_string(mesh.tets.rows()) +
      " tets (" + std::to_string(core::seconds_since(t_start)) + " s)");
  // 2. The twin and its validation.
  const auto progress = [&](double done, double end) {
    if (!args.quiet) report_progress("reduce: validation (full model)", done, end);
  };
  const studies::ReduceReport report =
      studies::reduce_case(mesh, spec, {args.quick_validation, say, progress});
  // 3. Write.
  io::write_reduce(out.path(), report, spec, mesh, args.case_file, core::seconds_since(t_start));
  out.commit();
  say("done in " + std::to_string(core::seconds_since(t_start)) + " s -> " + args.out.string());
  if (!report.passes)
    std::cerr << "thermotwin: reduce: warning: the reduced model is outside its limits on some "
                 "validation runs (validation.csv)\n";
  return 0;
}

}  // namespace tt::app
