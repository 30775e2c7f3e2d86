// thermotwin fit: how well a thermal-error model fed by m sensors predicts the drift on duty
// cycles it was not fitted on (DB3401/T 326-2024 metrics S, S_M, S_sigma).
//   thermotwin fit CASE --out DIR [--hours 5] [--required-sm-um 1] [--quick]
// Writes fit.json, modelling_record.{json,md}, compensation.csv, sensor_count_<target>.csv and
// sensor_count_<target>.png, campaign.csv (what each group was), held_out/<group>_temperatures.csv
// (the test groups' sensor readings). A case with feed-axis points
// (GM-1) also gets models of the error at those points and the axis polynomial fitted from their
// predictions (fit.json "axis", axis_fit.md); with --network, the patent's one network for every
// output, network_all_outputs.pt.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <set>

#include "app/commands.hpp"
#include "app/study.hpp"
#include "core/errors.hpp"
#include "core/units.hpp"
#include "fitting/group.hpp"
#include "fitting/metrics.hpp"
#include "fitting/models.hpp"
#include "fitting/noise.hpp"
#include "fitting/selection.hpp"
#include "io/atomic_dir.hpp"
#include "io/axis_fit_out.hpp"
#include "io/case_reader.hpp"
#include "io/csv_out.hpp"
#include "io/fitting_out.hpp"
#include "io/network_out.hpp"
#include "io/reports.hpp"
#include "mesh/mesher.hpp"
#include "placement/place.hpp"
#include "solvers/campaign.hpp"
#include "studies/axis_fit.hpp"
#include "studies/network_candidate.hpp"
#include "studies/placement_input.hpp"

namespace tt::app {
namespace {

/// Which campaign runs fit, validate and test (by name; runs not listed are not used).
const std::vector<std::string> kFitting{"p1_extended", "staircase_up", "irregular_a", "warm_start"};
const std::vector<std::string> kValidation{"staircase_down", "ambient_drift"};
const std::vector<std::string> kTest{"irregular_b", "run_then_cool", "mixed_speeds"};

/// The case's targets at the TCP, then the error at each feed-axis point (axis_target_names).
fitting::Group group_of(const core::CaseSpec& spec, const solvers::CampaignResult& r) {
  const Histories h = histories_from_points(spec, r.times, r.point_temperature, r.error);
  fitting::Group g;
  g.name = r.name;
  g.time = h.times;
  g.temperature = h.temperature;
  g.error.resize(h.targets.rows(), h.targets.cols() + r.axis.values.cols());
  g.error.leftCols(h.targets.cols()) = h.targets;
  g.error.rightCols(r.axis.values.cols()) = r.axis.values;
  g.sensor_names = h.names;
  g.target_names = h.target_names;
  for (const auto& name : studies::axis_target_names(spec)) g.target_names.push_back(name);
  return g;
}

std::vector<int> indices_of(const std::vector<fitting::Group>& groups,
                            const std::vector<std::string>& names) {
  std::vector<int> out;
  for (const auto& n : names)
    for (size_t i = 0; i < groups.size(); ++i)
      if (groups[i].name == n) out.push_back(static_cast<int>(i));
  return out;
}

/// Placement for the first `targets` targets on the fitting groups laid end to end.
placement::PlacementResult placement_on(const std::vector<fitting::Group>& groups,
                                        const std::vector<int>& fit,
                                        const Eigen::MatrixX3d& positions, Eigen::Index targets,
                                        std::uint64_t seed) {
  placement::PlacementOptions options;
  options.samples = 0;  // every reading of the campaign, not the patent's 100
  options.seed = seed;
  return placement::place_all(studies::groups_end_to_end(groups, fit, positions, targets), options);
}

/// Sensor sets per placement method and m for one target, as fitting takes them.
std::vector<fitting::SensorSet> sensor_sets(const placement::PlacementResult& p, int target,
                                            int max_m) {
  std::vector<fitting::SensorSet> sets;
  for (const auto& s : p.targets[target].selections) {
    if (s.m > max_m) continue;
    sets.push_back({std::string(placement::method_name(s.method)), s.columns});
  }
  return sets;
}

/// The sensors of several sets, each once, in the order first met.
std::vector<int> sensor_union(const std::vector<fitting::SensorSet>& sets) {
  std::vector<int> out;
  for (const auto& s : sets)
    for (int c : s.sensors)
      if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
  return out;
}

}  // namespace

int fit_command(const FitArgs& args) {
  // 1. The case and its mesh.
  const core::CaseSpec spec = io::read_case(args.case_file);
  std::vector<std::filesystem::path> inputs = io::case_input_files(spec);
  if (!args.rom.empty()) inputs.push_back(args.rom);
  io::OutputDir out(args.out, inputs);  // refused at once, not after the work
  const mesh::TetMesh mesh = mesh::mesh_case(spec);
  // 2. The virtual test campaign, with sensor noise on every reading.
  const auto runs = solvers::campaign_runs(spec, args.hours, spec.seed);
  const CampaignOnModel campaign =
      campaign_on_model(mesh, spec, runs, {args.rom, args.full}, {}, args.quiet);
  const auto& results = campaign.results;
  std::vector<fitting::Group> groups;
  for (size_t i = 0; i < results.size(); ++i)
    groups.push_back(
        fitting::noisy_group(group_of(spec, results[i]), fitting::SensorNoise{}, spec.seed, i));
  fitting::Split split{indices_of(groups, kFitting), indices_of(groups, kValidation),
                       indices_of(groups, kTest)};
  fitting::require_valid_split(split, static_cast<int>(groups.size()));
  // 3. Placement on the fitting groups only.
  const Histories first =
      histories_from_points(spec, results[0].times, results[0].point_temperature, results[0].error);
  const auto tcp_targets = static_cast<int>(first.target_names.size());
  const placement::PlacementResult placed =
      placement_on(groups, split.fitting, first.positions, tcp_targets, spec.seed);
  // 4. Per target: choose model, settings and placement method on validation; test; count sensors.
  const std::vector<fitting::ModelSpec> specs =
      args.quick ? std::vector<fitting::ModelSpec>{fitting::ModelSpec{}}
                 : fitting::default_model_candidates();
  std::map<std::string, studies::NetworkFigures> networks;
  std::vector<fitting::Evaluation> evals;
  std::vector<fitting::SensorCountTable> tables;
  nlohmann::json summary = nlohmann::json::object();
  std::vector<fitting::SensorSet> tcp_chosen, network_inputs;
  for (int target = 0; target < tcp_targets; ++target) {
    // The standard's own choice (7.1: |r| of the increments, pooled over the fitting groups) is
    // named apart from the placement module's correlation ranking (which leaves twins out), so
    // that the two never share a column of sensor_count_<target>.csv.
    const auto standard_sets = [&](int count) {
      auto sets = fitting::correlation_sensor_sets(fitting::group_subset(groups, split.fitting),
                                                   target, count);
      for (auto& s : sets) s.method = "db3401_correlation";
      return sets;
    };
    std::vector<fitting::SensorSet> at_most_4 = sensor_sets(placed, target, 4);
    const auto corr = standard_sets(4);
    at_most_4.insert(at_most_4.end(), corr.begin(), corr.end());
    if (args.network) {
      const auto grey = studies::network_sensor_sets(placed, target);
      at_most_4.insert(at_most_4.end(), grey.begin(), grey.end());
      network_inputs.insert(network_inputs.end(), grey.begin(), grey.end());
    }
    evals.push_back(fitting::evaluation(groups, split, target, at_most_4, specs));
    if (args.network) {
      // The network on the grey relational sensors, on the chosen linear model's (that model its
      // linear skip) and on the best ridge's (that ridge its skip), chosen on validation beside
      // the linear models.
      const fitting::Candidate linear_inputs =
          studies::linear_inputs_network(evals.back().model, spec.seed);
      at_most_4.push_back(linear_inputs.sensor_set);
      network_inputs.push_back(linear_inputs.sensor_set);
      std::vector<fitting::ModelSpec> with_network = specs;
      with_network.push_back(studies::driver_network_spec(spec.seed));
      with_network.push_back(linear_inputs.spec);
      if (auto c = studies::ridge_skip_network(evals.back(), spec.seed,
                                               !groups.front().input_names.empty())) {
        at_most_4.push_back(c->sensor_set);
        with_network.push_back(c->spec);
      }
      evals.back() = fitting::evaluation(groups, split, target, at_most_4, with_network);
    }
    std::vector<fitting::SensorSet> all = sensor_sets(placed, target, 6);
    const auto corr6 = standard_sets(6);
    all.insert(all.end(), corr6.begin(), corr6.end());
    tables.push_back(
        fitting::sensor_count_table(groups, split, target, all, specs, args.required_sm_um * 1e-6));
    const auto& e = evals.back();
    const double drift = studies::uncompensated_std(groups, split.test, target);
    const auto& chosen = e.sensor_sets[e.selection.candidates[e.selection.best].sensor_set];
    tcp_chosen.push_back({"tcp_" + groups[0].target_names[target] + "_chosen", chosen.sensors});
    std::vector<std::string> names;
    for (int c : chosen.sensors) names.push_back(groups[0].sensor_names[c]);
    summary[groups[0].target_names[target]] = {{"method", chosen.method},
                                               {"sensors", names},
                                               {"model", fitting::model_label(e.model.spec)},
                                               {"test_sm_um", e.test.sm * 1e6},
                                               {"test_s_sigma_um", e.test.s_sigma * 1e6},
                                               {"uncompensated_std_um", drift * 1e6},
                                               {"test_sm_over_uncompensated", e.test.sm / drift}};
    if (args.network) {
      // The network's own held-out figures beside the chosen model's, on the same groups.
      std::vector<int> refit = split.fitting;
      refit.insert(refit.end(), split.validation.begin(), split.validation.end());
      if (auto n = studies::network_figures(e, fitting::group_subset(groups, refit),
                                            fitting::group_subset(groups, split.test))) {
        const std::string& name = groups[0].target_names[target];
        summary[name]["network"] = io::network_json(*n);
        summary[name]["network"]["test_sm_over_uncompensated"] = n->test.sm / drift;
        summary[name]["network"]["file"] = "network_" + name + ".pt";
        networks.emplace(name, std::move(*n));
      }
    }
  }
  // 5. The feed axis: models at its points and the polynomial from their predictions.
  std::optional<studies::AxisFit> axis;
  double axis_seconds = 0.0;
  if (!spec.mechanical.axis_points.empty()) {
    const auto start = std::chrono::steady_clock::now();
    std::optional<fitting::ModelSpec> network;
    if (args.network && !network_inputs.empty()) network = studies::driver_network_spec(spec.seed);
    axis = studies::axis_fit(spec, groups, split, tcp_targets, tcp_chosen, specs, network,
                             sensor_union(network_inputs));
    axis_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  // 6. Outputs, all or nothing.
  const auto& dir = out.path();
  io::write_fit_json(dir / "fit.json", evals, tables);
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(dir / "fit.json"));
  doc["summary"] = summary;
  doc["model"] = campaign.model;
  doc["campaign"] = nlohmann::json::array();
  for (const auto& r : runs)
    doc["campaign"].push_back({{"name", r.name},
                               {"shape", r.shape},
                               {"hours", r.spec.duty_cycle.end / 3600.0},
                               {"initial_temperature_degC", r.spec.thermal.initial_temperature_c}});
  if (axis) {
    doc["axis"] = io::axis_fit_json(*axis);
    doc["axis"]["seconds"] = axis_seconds;  // the axis points' models, network and polynomials
    if (!axis->network.empty()) doc["axis"]["network"]["file"] = "network_all_outputs.pt";
    io::write_file_atomically(dir / "axis_fit.md", io::axis_fit_markdown(*axis));
    if (!axis->network.empty())
      std::get<torchnet::Network>(axis->network.front().body)
          .save_torchscript(dir / "network_all_outputs.pt");
  }
  io::write_json(dir / "fit.json", doc);
  for (const auto& [name, n] : networks)
    std::get<torchnet::Network>(n.model.body).save_torchscript(dir / ("network_" + name + ".pt"));
  io::ModellingConditions conditions;
  conditions.machine_model = spec.machine.empty() ? spec.name : spec.machine;
  conditions.machine_number = "virtual";
  conditions.modelling_date = io::modelling_date_today();
  conditions.initial_ambient_temperature =
      spec.thermal.initial_temperature_c + core::kCelsiusOffset;
  double max_speed = 0;
  for (const auto& r : runs)
    for (const auto& s : r.spec.duty_cycle.segments) max_speed = std::max(max_speed, s.speed_rpm);
  conditions.max_spindle_speed = max_speed * 2 * 3.14159265358979323846 / 60;
  io::write_modelling_record(dir / "modelling_record.json", dir / "modelling_record.md", conditions,
                             evals);
  std::vector<fitting::FittedModel> models;
  for (const auto& e : evals) models.push_back(e.model);
  io::write_compensation_csv(dir / "compensation.csv", models, groups);
  // The held-out groups' sensor readings: the temperature states on which `thermotwin export
  // --states` judges the controllers' laws (docs/cnc-export.md).
  std::filesystem::create_directories(dir / "held_out");
  for (int i : split.test) {
    const fitting::Group& g = groups[static_cast<std::size_t>(i)];
    std::vector<std::string> header{"time_s"};
    header.insert(header.end(), g.sensor_names.begin(), g.sensor_names.end());
    Eigen::MatrixXd rows(g.time.size(), g.temperature.cols() + 1);
    rows << g.time, g.temperature.array() - core::kCelsiusOffset;  // °C, as measured data
    io::write_csv(dir / "held_out" / (g.name + "_temperatures.csv"), header, rows);
  }
  for (const auto& t : tables) {
    std::set<std::string> methods;
    for (const auto& row : t.rows) methods.insert(row.method);
    std::vector<std::string> header{"m"};
    for (const auto& m : methods) header.push_back(m + "_test_sm_um");
    int max_m = 0;
    for (const auto& row : t.rows) max_m = std::max(max_m, row.m);
    Eigen::MatrixXd rows =
        Eigen::MatrixXd::Constant(max_m, static_cast<Eigen::Index>(header.size()), std::nan(""));
    for (int m = 1; m <= max_m; ++m) rows(m - 1, 0) = m;
    for (const auto& row : t.rows) {
      const auto col = 1 + std::distance(methods.begin(), methods.find(row.method));
      rows(row.m - 1, col) = row.test_sm * 1e6;
    }
    const std::string stem = "sensor_count_" + t.target_name;
    io::write_csv(dir / (stem + ".csv"), header, rows);
    std::string cols;
    for (size_t i = 1; i < header.size(); ++i) cols += (i > 1 ? "," : "") + header[i];
    plot({"lines", (dir / (stem + ".csv")).string(), (dir / (stem + ".png")).string(), "--x", "m",
          "--columns=" + cols, "--xlabel", "sensors m", "--ylabel", "test S_M [um]",
          "--title=test accuracy by number of sensors, target " + t.target_name});
  }
  out.commit();
  std::cerr << "thermotwin: fit: " << summary.dump() << "\n";
  return 0;
}

}  // namespace tt::app
