// thermotwin place: where to put temperature sensors.
//   thermotwin place CASE --out DIR          simulate the case, then place sensors on its
//   candidates thermotwin place --from RUNDIR --out DIR place sensors on a finished run's histories
// The candidates are the case's named points, or with [placement] candidates = "surface" the
// vertices of the chosen surfaces (docs/placement.md). --methods observer_variance also places for
// the physics observer (its posterior variance of each target) on the reduced model (--rom, or
// built on the fly).
// Writes placement.json, mi_ranking.csv, candidates_mi.vtp and mi_bars_<target>.png.
#include <chrono>
#include <iostream>
#include <optional>

#include "app/commands.hpp"
#include "app/study.hpp"
#include "core/errors.hpp"
#include "core/timing.hpp"
#include "fitting/noise.hpp"
#include "io/atomic_dir.hpp"
#include "io/case_reader.hpp"
#include "io/placement_out.hpp"
#include "io/reduced_model_io.hpp"
#include "io/reports.hpp"
#include "io/vtk_out.hpp"
#include "mesh/mesher.hpp"
#include "placement/place.hpp"
#include "solvers/campaign.hpp"
#include "studies/estimation_input.hpp"

namespace tt::app {

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

namespace {

/// The histories as the campaign's sensors would read them (fitting::SensorNoise defaults),
/// reproducible from the case's seed.
Histories with_sensor_noise(Histories h, std::uint64_t seed) {
  fitting::Group g;
  g.name = "place";
  g.time = h.times;
  g.temperature = h.temperature;
  g.error = h.targets;
  g.sensor_names = h.names;
  g.target_names = h.target_names;
  constexpr std::uint64_t kPlaceStream = 0x706c616365;  // "place"
  const fitting::Group noisy = fitting::noisy_group(g, fitting::SensorNoise{}, seed, kPlaceStream);
  h.temperature = noisy.temperature;
  h.targets = noisy.error;
  return h;
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

/// The physics observer's model for placement for estimation: on the reduced model (`rom`, or
/// built on the fly), the case's duty cycle read at every output time, the campaign's sensor
/// noise and the observer's default process noise. `record` gets the settings.
placement::EstimationProblem estimation_problem(const core::CaseSpec& spec, const Histories& h,
                                                const std::filesystem::path& rom,
                                                nlohmann::json& record) {
  const mesh::TetMesh mesh = mesh::mesh_case(spec);
  solvers::Twin twin;
  if (rom.empty()) {
    twin = solvers::case_twin(mesh, spec);
  } else {
    io::ReducedModelFile file = io::read_reduced_model(rom);
    io::check_reduced_model_fits(file, io::reduced_model_key(spec, mesh), rom);
    twin = std::move(file.twin);
  }
  const solvers::ObserverNoise noise;
  const studies::EstimationCandidates candidates{h.names, h.nodes,
                                                 fitting::SensorNoise{}.temperature_sigma};
  record = {{"order", twin.model.states()},
            {"rom", rom.empty() ? std::string("built on the fly") : rom.string()},
            {"reading_interval_s", spec.thermal.output_interval},
            {"sensor_sigma_K", candidates.sensor_sigma_k},
            {"heat_walk_W_per_sqrt_h", noise.heat_walk_w},
            {"air_walk_K_per_sqrt_h", noise.air_walk_k}};
  return studies::observer_estimation_problem(twin, {spec}, candidates, h.target_names, noise,
                                              spec.thermal.output_interval);
}

}  // namespace

placement::PlacementInput placement_input(const Histories& h) {
  placement::PlacementInput in;
  for (size_t c = 0; c < h.names.size(); ++c)
    in.ids.push_back(core::SensorId{static_cast<int>(c) + 1});
  in.positions_m = h.positions;
  in.times_s = h.times;
  in.temperatures_K = h.temperature;
  for (size_t k = 0; k < h.target_names.size(); ++k)
    in.targets.push_back({h.target_names[k], h.targets.col(static_cast<Eigen::Index>(k))});
  return in;
}

int place_command(const PlaceArgs& args) {
  // 1. Candidate histories: simulate the case, or read a finished run. The output is claimed
  //    first: one that is refused fails before any work, as does a method that is not one.
  const std::vector<placement::Method> methods = methods_named(args.methods);
  core::CaseSpec spec;
  Histories h;
  std::optional<io::OutputDir> out;
  nlohmann::json model_used{{"kind", "a finished run's histories"}};
  if (!args.from_run.empty()) {
    out.emplace(args.out, std::vector<std::filesystem::path>{args.from_run});
    h = histories_from_run(args.from_run);
    spec = io::read_case(args.from_run / "case.resolved.toml");
  } else {
    spec = io::read_case(args.case_file);
    std::vector<std::filesystem::path> inputs = io::case_input_files(spec);
    if (!args.rom.empty()) inputs.push_back(args.rom);
    out.emplace(args.out, inputs);
    h = simulated_histories(spec, {args.rom, args.full}, args.quiet, model_used);
  }
  // Simulated histories are exact, and a thermal field driven by a few sources lies in a
  // subspace of few dimensions: beyond its rank no further sensor is admissible. Real readings
  // carry noise; --sensor-noise places on such readings.
  if (args.sensor_noise) h = with_sensor_noise(std::move(h), spec.seed);
  // 2. Every placement method, for each target and m = 1..m_max.
  placement::PlacementOptions options;
  options.samples = args.samples;
  options.temperature_bins = args.bins;
  options.error_bins = args.bins;
  options.m_max = args.m_max;
  options.seed = spec.seed;
  options.methods = methods;
  placement::PlacementInput input = placement_input(h);
  nlohmann::json estimation;
  if (std::find(methods.begin(), methods.end(), placement::Method::kObserverVariance) !=
      methods.end())
    input.estimation = estimation_problem(spec, h, args.rom, estimation);
  const auto t_place = std::chrono::steady_clock::now();
  const placement::PlacementResult result = placement::place_all(input, options);
  const double place_s = core::seconds_since(t_place);

  // 3. Outputs, all or nothing.
  const auto& dir = out->path();
  nlohmann::json doc = io::placement_json(result);
  doc["sensor_noise"] = args.sensor_noise;
  doc["model"] = model_used;
  if (input.estimation) doc["observer_variance"] = estimation;
  doc["candidates"] = nlohmann::json::array();
  for (size_t c = 0; c < h.names.size(); ++c) {
    nlohmann::json entry{{"id", c + 1},
                         {"name", h.names[c]},
                         {"position_m", {h.positions(c, 0), h.positions(c, 1), h.positions(c, 2)}}};
    if (h.nodes[c] >= 0) entry["node"] = h.nodes[c];
    doc["candidates"].push_back(std::move(entry));
  }
  io::write_json(dir / "placement.json", doc);
  io::write_mi_ranking_csv(dir / "mi_ranking.csv", result);
  std::vector<io::NamedField> fields;
  for (const auto& t : result.targets) {
    fields.push_back({"mi_bits_" + t.target, 1, t.mi_bits});
    Eigen::VectorXd rank(static_cast<Eigen::Index>(t.mi_rank.size()));
    for (size_t c = 0; c < t.mi_rank.size(); ++c) rank(static_cast<Eigen::Index>(c)) = t.mi_rank[c];
    fields.push_back({"mi_rank_" + t.target, 1, rank});
  }
  io::write_point_cloud_vtp(dir / "candidates_mi.vtp", h.names, h.positions, fields);
  // Thousands of surface candidates make an unreadable bar chart: then the best 50.
  const bool many = h.names.size() > 60;
  for (const auto& t : result.targets) {
    std::vector<std::string> bars{"bars",
                                  (dir / "mi_ranking.csv").string(),
                                  (dir / ("mi_bars_" + t.target + ".png")).string(),
                                  "--label",
                                  "id",
                                  "--value=mi_bits_" + t.target,
                                  "--title=" + std::string(many ? "best 50 candidates: " : "") +
                                      "single-sensor mutual information with " + t.target +
                                      " (formula 1)"};
    if (many) bars.insert(bars.end(), {"--sort", "--top", "50"});
    plot(bars);
  }
  out->commit();
  std::cerr << "thermotwin: place: " << h.names.size() << " candidates x "
            << result.sample_times_s.size() << " samples, placement " << place_s << " s -> "
            << args.out.string() << "\n";
  return 0;
}

}  // namespace tt::app
