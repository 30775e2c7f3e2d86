// thermotwin reduce CASE --out DIR: the case's reduced-order twin (docs/reduced-order.md).
//   1. read the case and mesh it;
//   2. assemble the full thermal system and, for the thermal error, factor the stiffness once to
//      get the TCP, probe and axis points' influence rows;
//   3. build the reduced basis and project the system and the outputs on it;
//   4. judge it against the full model on duty cycles that were not used to build it;
//   5. write reduced_model.json / .bin and validation.csv, all or nothing.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include "app/commands.hpp"
#include "core/timing.hpp"
#include "io/atomic_dir.hpp"
#include "io/case_reader.hpp"
#include "io/csv_out.hpp"
#include "io/reduced_model_io.hpp"
#include "mesh/mesher.hpp"
#include "solvers/campaign.hpp"
#include "solvers/twin.hpp"

namespace tt::app {

using core::seconds_since;
namespace {

using Clock = std::chrono::steady_clock;
nlohmann::json validation_json(const std::vector<solvers::TwinComparison>& table) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& c : table) {
    nlohmann::json drift = nlohmann::json::object();
    for (std::size_t k = 0; k < c.drift_names.size(); ++k) {
      const auto i = static_cast<Eigen::Index>(k);
      drift[c.drift_names[k]] = {{"max_error_um", c.drift_error_m(i) * 1e6},
                                 {"peak_um", c.drift_peak_m(i) * 1e6},
                                 {"limit_um", c.drift_limit_m(i) * 1e6}};
    }
    rows.push_back({{"run", c.run},
                    {"shape", c.shape},
                    {"max_temperature_error_K", c.max_temperature_error_k},
                    {"worst_point", c.worst_point},
                    {"temperature_limit_K", 0.01},
                    {"drift", drift},
                    {"passes", c.passes()}});
  }
  return rows;
}

/// validation.csv: one row per run and output column (temperatures as one row).
void write_validation_csv(const std::filesystem::path& path,
                          const std::vector<solvers::TwinComparison>& table) {
  std::ostringstream o;
  o << std::setprecision(6) << "run,output,max_error,limit,peak,unit,passes\n";
  for (const auto& c : table) {
    o << c.run << ",temperatures," << c.max_temperature_error_k << ",0.01,,K,"
      << (c.max_temperature_error_k <= 0.01 ? "yes" : "no") << "\n";
    for (std::size_t k = 0; k < c.drift_names.size(); ++k) {
      const auto i = static_cast<Eigen::Index>(k);
      o << c.run << "," << c.drift_names[k] << "," << c.drift_error_m(i) * 1e6 << ","
        << c.drift_limit_m(i) * 1e6 << "," << c.drift_peak_m(i) * 1e6 << ",um,"
        << (c.drift_error_m(i) <= c.drift_limit_m(i) ? "yes" : "no") << "\n";
    }
  }
  io::write_file_atomically(path, o.str());
}

}  // namespace

int reduce_command(const ReduceArgs& args) {
  const auto t_start = Clock::now();
  const auto say = [&](const std::string& what) {
    if (!args.quiet) std::cerr << "thermotwin: reduce: " << what << "\n";
  };
  // 1. Read the case, claim the output (refused at once when it is not ours), mesh.
  const core::CaseSpec spec = io::read_case(args.case_file);
  io::OutputDir out(args.out, io::case_input_files(spec));
  const mesh::TetMesh mesh = mesh::mesh_case(spec);
  say(std::to_string(mesh.nodes.rows()) + " nodes, " + std::to_string(mesh.tets.rows()) +
      " tets (" + std::to_string(seconds_since(t_start)) + " s)");
  // 2. Full system and output rows.
  auto t = Clock::now();
  const solvers::FullThermalSystem full = solvers::thermal_system(mesh, spec);
  std::optional<solvers::ElasticModel> elastic;
  if (spec.mechanical.enabled && !spec.mechanical.tcp_point.empty()) {
    say("factoring the stiffness for the TCP's influence rows");
    elastic.emplace(mesh, spec);
  }
  const solvers::TwinOutputs full_out =
      solvers::full_outputs(mesh, spec, elastic ? &*elastic : nullptr);
  elastic.reset();  // the factor is the largest thing in memory: gone before the basis
  const double outputs_s = seconds_since(t);
  // 3. The reduced model.
  say("building the basis");
  t = Clock::now();
  const solvers::Twin twin = solvers::build_twin(full, spec, full_out);
  const double reduce_s = seconds_since(t);
  say("order " + std::to_string(twin.model.states()) + " (" + std::to_string(reduce_s) + " s)");
  // 4. Validation against the full model.
  t = Clock::now();
  const auto runs = args.quick_validation
                        ? std::vector<solvers::CampaignRun>{{"own_cycle", "the case's own", spec}}
                        : solvers::validation_runs(spec, spec.seed);
  const auto table = solvers::validate_twin(full, full_out, twin, runs, [&](double d, double e) {
    if (!args.quiet) report_progress("reduce: validation (full model)", d, e);
  });
  const double validate_s = seconds_since(t);
  bool all_pass = true;
  for (const auto& c : table) {
    all_pass = all_pass && c.passes();
    say(c.run + ": max |dT| " + std::to_string(c.max_temperature_error_k) + " K at " +
        c.worst_point + (c.passes() ? " (within limits)" : " (OUTSIDE the limits)"));
  }
  // 5. Write.
  io::ReducedModelFile file;
  file.twin = twin;
  file.key = io::reduced_model_key(spec, mesh);
  file.case_name = spec.name;
  file.case_file = std::filesystem::absolute(args.case_file).string();
  file.info["validation"] = validation_json(table);
  file.info["validation_passes"] = all_pass;
  file.info["timings"] = {{"outputs_s", outputs_s},
                          {"reduce_s", reduce_s},
                          {"validate_s", validate_s},
                          {"total_s", seconds_since(t_start)}};
  io::write_reduced_model(out.path(), file);
  write_validation_csv(out.path() / "validation.csv", table);
  out.commit();
  say("done in " + std::to_string(seconds_since(t_start)) + " s -> " + args.out.string());
  if (!all_pass)
    std::cerr << "thermotwin: reduce: warning: the reduced model is outside its limits on some "
                 "validation runs (validation.csv)\n";
  return 0;
}

}  // namespace tt::app
