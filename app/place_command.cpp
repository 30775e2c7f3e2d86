// thermotwin place: where to put temperature sensors.
//   thermotwin place CASE --out DIR          simulate the case, then place sensors on its
//   candidates thermotwin place --from RUNDIR --out DIR place sensors on a finished run's histories
// The candidates are the case's named points, or with [placement] candidates = "surface" the
// vertices of the chosen surfaces (docs/placement.md). --methods observer_variance also places for
// the physics observer (its posterior variance of each target) on the reduced model (--rom, or
// built on the fly).
// 1. The candidates' histories: a finished run's, or the case simulated on the chosen model.
// 2. The study (studies/place_sensors.hpp): every placement method for each target and
//    m = 1..m_max, on readings with the campaign's sensor noise with --sensor-noise.
// 3. placement.json, mi_ranking.csv, candidates_mi.vtp and mi_bars_<target>.png
//    (io/place_out.hpp), all or nothing.
#include <algorithm>
#include <iostream>
#include <optional>

#include "app/commands.hpp"
#include "app/study.hpp"
#include "core/errors.hpp"
#include "io/atomic_dir.hpp"
#include "io/case_reader.hpp"
#include "io/place_out.hpp"
#include "io/reduced_model_io.hpp"
#include "mesh/mesher.hpp"
#include "studies/place_sensors.hpp"

namespace tt::app {
namespace {

/// The case's candidate histories under its duty cycle, on the model `model` names; `used` gets
/// which model that was.
Histories simulated_histories(const core::CaseSpec& spec, const ModelChoice& model, bool quiet,
                              nlohmann::json& used) {
  const mesh::TetMesh mesh = mesh::mesh_case(spec);
  const CandidateSet candidates = candidate_set(spec, mesh);
  const std::vector<solvers::CampaignRun> runs{{"case", "the case's duty cycle", spec}};
  CampaignOnModel campaign = campaign_on_model(mesh, spec, runs, model, candidates.nodes, quiet);
  used = std::move(campaign.model);
  const auto& results = campaign.results;
  return histories_from_nodes(spec, candidates, results[0].times, results[0].node_temperature,
                              results[0].error);
}

/// The methods --methods names; none named: every method but observer_variance (which needs the
/// reduced model). Throws CaseError naming a name that is not a method.
std::vector<placement::Method> methods_named(const std::vector<std::string>& names) {
  std::vector<placement::Method> methods;
  for (const auto& name : names) {
    const auto m = core::value_in(placement::kMethodNames, name);
    if (!m)
      throw core::CaseError("place --methods: '" + name + "' is not a method; expected " +
                            core::names_list(placement::kMethodNames));
    methods.push_back(*m);
  }
  if (names.empty())
    for (const auto m : placement::all_methods())
      if (m != placement::Method::kObserverVariance) methods.push_back(m);
  return methods;
}

/// The reduced model of observer_variance: read from `rom` and checked against the case, or built
/// on the fly.
solvers::Twin estimation_twin(const core::CaseSpec& spec, const mesh::TetMesh& mesh,
                              const std::filesystem::path& rom) {
  if (rom.empty()) return solvers::case_twin(mesh, spec);
  io::ReducedModelFile file = io::read_reduced_model(rom);
  io::check_reduced_model_fits(file, io::reduced_model_key(spec, mesh), rom);
  return std::move(file.twin);
}

/// The candidates' histories (and the case) of a finished run or of the case simulated, with the
/// output claimed first: one that is refused fails before any work.
struct Candidates {
  core::CaseSpec spec;
  Histories histories;
  nlohmann::json model{{"kind", "a finished run's histories"}};
};

Candidates candidates_of(const PlaceArgs& args, std::optional<io::OutputDir>& out) {
  Candidates c;
  if (!args.from_run.empty()) {
    out.emplace(args.out, std::vector<std::filesystem::path>{args.from_run});
    c.histories = histories_from_run(args.from_run);
    c.spec = io::read_case(args.from_run / "case.resolved.toml");
    return c;
  }
  c.spec = io::read_case(args.case_file);
  std::vector<std::filesystem::path> inputs = io::case_input_files(c.spec);
  if (!args.rom.empty()) inputs.push_back(args.rom);
  out.emplace(args.out, inputs);
  c.histories = simulated_histories(c.spec, {args.rom, args.full}, args.quiet, c.model);
  return c;
}

/// The sizes `args` asks the catalogue's effects to be seen at; the defaults where it is silent.
studies::CatalogueSizes catalogue_sizes(const PlaceArgs& args) {
  studies::CatalogueSizes s;
  s.heat_w = args.detect_heat_w.value_or(s.heat_w);
  s.film_share = args.detect_film_share.value_or(s.film_share);
  s.source_coefficient_per_k = args.detect_source_per_k.value_or(s.source_coefficient_per_k);
  s.material_change = args.detect_material_change.value_or(s.material_change);
  s.air_k = args.detect_air_k.value_or(s.air_k);
  return s;
}

}  // namespace

int place_command(const PlaceArgs& args) {
  // 1. Candidate histories (a method that is not one fails before any work).
  const std::vector<placement::Method> methods = methods_named(args.methods);
  std::optional<io::OutputDir> out;
  const Candidates c = candidates_of(args, out);
  const bool estimation = std::find(methods.begin(), methods.end(),
                                    placement::Method::kObserverVariance) != methods.end();
  std::optional<mesh::TetMesh> mesh;
  if (estimation || args.catalogue_detection) mesh = mesh::mesh_case(c.spec);
  std::optional<solvers::Twin> twin;
  if (estimation) twin = estimation_twin(c.spec, *mesh, args.rom);
  // 2. Every placement method, for each target and m = 1..m_max.
  const studies::PlaceReport report = studies::place_sensors(
      {&c.spec, c.histories, methods, args.samples, args.bins, args.m_max, args.sensor_noise,
       twin ? &*twin : nullptr, args.catalogue_detection ? &*mesh : nullptr, catalogue_sizes(args),
       args.quiet ? solvers::Progress{} : [](double done, double total) {
         report_progress("place: the catalogue's effects for detection", done, total);
       },
       args.quiet ? studies::Progress{} : [](const std::string& line) {
         std::cerr << "thermotwin: place: " << line << "\n";
       }});
  // 3. Outputs, all or nothing.
  io::write_place(out->path(), report, {args.sensor_noise, c.model, args.rom});
  out->commit();
  std::cerr << "thermotwin: place: " << report.histories.names.size() << " candidates x "
            << report.result.sample_times_s.size() << " samples, placement " << report.place_s
            << " s -> " << args.out.string() << "\n";
  return 0;
}

}  // namespace tt::app
