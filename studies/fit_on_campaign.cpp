#include "studies/fit_on_campaign.hpp"

#include <algorithm>

#include "core/timing.hpp"
#include "fitting/models.hpp"
#include "fitting/noise.hpp"
#include "placement/place.hpp"
#include "studies/estimation_input.hpp"
#include "studies/histories.hpp"
#include "studies/placement_input.hpp"

namespace tt::studies {
namespace {

/// Which campaign runs (solvers::campaign_runs' names) fit, validate and test; runs not listed
/// are not used.
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
  for (const auto& name : axis_target_names(spec)) g.target_names.push_back(name);
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

/// Placement for estimation on the campaign's reduced model: the physics observer (its default
/// process noise, the campaign's sensor noise) over the fitting runs' duty cycles, read every
/// output interval but at least every 300 s (the criterion's cost grows with the readings).
placement::EstimationProblem fitting_estimation(const core::CaseSpec& spec, const Histories& h,
                                                const CampaignFitOptions& o,
                                                const std::vector<int>& fitting) {
  std::vector<core::CaseSpec> cycles;
  for (int i : fitting) cycles.push_back(o.runs->at(static_cast<std::size_t>(i)).spec);
  const EstimationCandidates candidates{h.names, h.nodes, fitting::SensorNoise{}.temperature_sigma};
  solvers::ObserverNoise noise;
  noise.sensor_sigma_k = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(h.names.size()),
                                                   candidates.sensor_sigma_k);
  return observer_estimation_problem(*o.twin, cycles, candidates, h.target_names, noise,
                                     std::max(spec.thermal.output_interval, 300.0), o.progress);
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

/// What every target's choice reads: the groups, their split, the placement on the fitting groups
/// and the model specs.
struct Context {
  const core::CaseSpec& spec;
  const CampaignFitOptions& options;
  const std::vector<fitting::Group>& groups;
  const fitting::Split& split;
  placement::PlacementResult placed;
  std::vector<fitting::ModelSpec> specs;
};

/// The placement sets of at most `count` sensors, then the standard's own choice (7.1: |r| of the
/// increments, pooled over the fitting groups), named apart from the placement module's
/// correlation ranking (which leaves twins out) so that the two never share a column of
/// sensor_count_<target>.csv.
std::vector<fitting::SensorSet> candidate_sets(const Context& c, int target, int count) {
  std::vector<fitting::SensorSet> sets = sensor_sets(c.placed, target, count);
  auto standard = fitting::correlation_sensor_sets(fitting::group_subset(c.groups, c.split.fitting),
                                                   target, count);
  for (auto& s : standard) s.method = "db3401_correlation";
  sets.insert(sets.end(), standard.begin(), standard.end());
  return sets;
}

/// The choice among the linear models and, with the network, the network on the grey relational
/// sensors, on the chosen linear model's (that model its linear skip) and on the best ridge's
/// (that ridge its skip), chosen on validation beside the linear models. `network_inputs`
/// gathers the network's sensor sets.
fitting::Evaluation target_evaluation(const Context& c, int target,
                                      std::vector<fitting::SensorSet>& network_inputs) {
  std::vector<fitting::SensorSet> sets = candidate_sets(c, target, 4);
  if (c.options.network) {
    const auto grey = network_sensor_sets(c.placed, target);
    sets.insert(sets.end(), grey.begin(), grey.end());
    network_inputs.insert(network_inputs.end(), grey.begin(), grey.end());
  }
  fitting::Evaluation e = fitting::evaluation(c.groups, c.split, target, sets, c.specs);
  if (!c.options.network) return e;
  const fitting::Candidate linear_inputs = linear_inputs_network(e.model, c.spec.seed);
  sets.push_back(linear_inputs.sensor_set);
  network_inputs.push_back(linear_inputs.sensor_set);
  std::vector<fitting::ModelSpec> with_network = c.specs;
  with_network.push_back(driver_network_spec(c.spec.seed));
  with_network.push_back(linear_inputs.spec);
  if (auto r = ridge_skip_network(e, c.spec.seed, !c.groups.front().input_names.empty())) {
    sets.push_back(r->sensor_set);
    with_network.push_back(r->spec);
  }
  return fitting::evaluation(c.groups, c.split, target, sets, with_network);
}

CampaignTargetFit target_fit(const Context& c, int target,
                             std::vector<fitting::SensorSet>& network_inputs) {
  CampaignTargetFit t;
  t.evaluation = target_evaluation(c, target, network_inputs);
  t.sensor_count = fitting::sensor_count_table(
      c.groups, c.split, target, candidate_sets(c, target, 6), c.specs, c.options.required_sm);
  t.uncompensated_std = uncompensated_std(c.groups, c.split.test, target);
  if (c.options.network) {
    // The network's own held-out figures beside the chosen model's, on the same groups.
    std::vector<int> refit = c.split.fitting;
    refit.insert(refit.end(), c.split.validation.begin(), c.split.validation.end());
    t.network = network_figures(t.evaluation, fitting::group_subset(c.groups, refit),
                                fitting::group_subset(c.groups, c.split.test));
  }
  return t;
}

}  // namespace

std::vector<fitting::Evaluation> CampaignFitReport::evaluations() const {
  std::vector<fitting::Evaluation> out;
  for (const auto& t : targets) out.push_back(t.evaluation);
  return out;
}

CampaignFitReport fit_on_campaign(const core::CaseSpec& spec,
                                  const std::vector<solvers::CampaignResult>& results,
                                  const CampaignFitOptions& options) {
  CampaignFitReport r;
  for (size_t i = 0; i < results.size(); ++i)
    r.groups.push_back(
        fitting::noisy_group(group_of(spec, results[i]), fitting::SensorNoise{}, spec.seed, i));
  r.split = {indices_of(r.groups, kFitting), indices_of(r.groups, kValidation),
             indices_of(r.groups, kTest)};
  fitting::require_valid_split(r.split, static_cast<int>(r.groups.size()));
  const Histories first =
      histories_from_points(spec, results[0].times, results[0].point_temperature, results[0].error);
  const auto tcp_targets = static_cast<int>(first.target_names.size());
  placement::PlacementOptions placing;
  placing.samples = 0;  // every reading of the campaign, not the patent's 100
  placing.seed = spec.seed;
  placement::PlacementInput placed =
      groups_end_to_end(r.groups, r.split.fitting, first.positions, tcp_targets);
  if (options.twin && options.runs)
    placed.estimation = fitting_estimation(spec, first, options, r.split.fitting);
  Context c{spec,
            options,
            r.groups,
            r.split,
            placement::place_all(placed, placing),
            options.quick ? std::vector<fitting::ModelSpec>{fitting::ModelSpec{}}
                          : fitting::default_model_candidates()};
  std::vector<fitting::SensorSet> tcp_chosen, network_inputs;
  for (int target = 0; target < tcp_targets; ++target) {
    r.targets.push_back(target_fit(c, target, network_inputs));
    const auto& e = r.targets.back().evaluation;
    const auto& chosen = e.sensor_sets[e.selection.candidates[e.selection.best].sensor_set];
    tcp_chosen.push_back({"tcp_" + r.groups[0].target_names[target] + "_chosen", chosen.sensors});
  }
  if (spec.mechanical.axis_points.empty()) return r;
  const auto start = std::chrono::steady_clock::now();
  std::optional<fitting::ModelSpec> network;
  if (options.network && !network_inputs.empty()) network = driver_network_spec(spec.seed);
  r.axis = axis_fit(spec, r.groups, r.split, tcp_targets, tcp_chosen, c.specs, network,
                    sensor_union(network_inputs));
  r.axis_seconds = core::seconds_since(start);
  return r;
}

}  // namespace tt::studies
