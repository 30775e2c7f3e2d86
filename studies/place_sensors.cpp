#include "studies/place_sensors.hpp"

#include <chrono>
#include <map>

#include "core/timing.hpp"
#include "fitting/noise.hpp"
#include "studies/estimation_input.hpp"

namespace tt::studies {
namespace {

/// The histories as the campaign's sensors would read them (fitting::SensorNoise defaults),
/// reproducible from `seed`.
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

/// The physics observer's model for placement for estimation on `twin`: the case's duty cycle
/// read at every output time, the campaign's sensor noise and the observer's default process
/// noise.
placement::EstimationProblem estimation_problem(const core::CaseSpec& spec, const Histories& h,
                                                const solvers::Twin& twin,
                                                EstimationSettings& settings) {
  const EstimationCandidates candidates{h.names, h.nodes, fitting::SensorNoise{}.temperature_sigma};
  settings = {twin.model.states(), spec.thermal.output_interval, candidates.sensor_sigma_k, {}};
  return observer_estimation_problem(twin, {spec}, candidates, h.target_names, settings.noise,
                                     spec.thermal.output_interval);
}

placement::PlacementOptions placement_options(const PlaceInput& input) {
  placement::PlacementOptions options;
  options.samples = input.samples;
  options.temperature_bins = input.bins;
  options.error_bins = input.bins;
  options.m_max = input.m_max;
  options.seed = input.spec->seed;
  options.methods = input.methods;
  options.progress = input.progress;
  return options;
}

/// Placement for detection on the estimation problem: the greedy from no sensor, and what each
/// target's observer_variance set of the largest m leaves unseen.
DetectionReport detection_report(const PlaceInput& input, const placement::EstimationProblem& p,
                                 const EstimationSettings& settings,
                                 const placement::PlacementResult& result) {
  DetectionReport d;
  const solvers::ConsistencyOptions alarm;
  d.bound_sigmas = alarm.model_residual_sigmas;
  d.sustain_s = alarm.sustain_s;
  d.problem = observer_detection_problem(*input.twin, p, *input.spec, settings.noise, d.sizes,
                                         d.sustain_s, settings.reading_interval_s);
  std::vector<int> pool(static_cast<std::size_t>(d.problem.held_sigmas.cols()));
  for (std::size_t c = 0; c < pool.size(); ++c) pool[c] = static_cast<int>(c);
  d.greedy = placement::detection_greedy(d.problem, {}, pool, input.m_max, d.bound_sigmas);
  for (const auto& t : result.targets) {
    const placement::Selection* largest = nullptr;
    for (const auto& s : t.selections)
      if (s.method == placement::Method::kObserverVariance && (!largest || s.m > largest->m))
        largest = &s;
    if (largest)
      d.unseen_by_estimation.emplace_back(
          t.target, placement::unseen_effects(d.problem, largest->columns, d.bound_sigmas));
  }
  return d;
}

/// Placement for detection of the catalogue's effects on the case's duty cycle: the greedy from
/// no sensor, and the kinds each method's set of the largest m sees.
CatalogueDetectionReport catalogue_detection_report(const PlaceInput& input, const Histories& h,
                                                    const placement::PlacementResult& result) {
  CatalogueDetectionReport d;
  const solvers::ConsistencyOptions alarm;
  d.bound_sigmas = alarm.model_residual_sigmas;
  d.settings.sustain_s = alarm.sustain_s;
  d.settings.sample_s = input.spec->thermal.output_interval;
  d.settings.sizes = input.catalogue_sizes;
  d.settings.sensor_sigma_k = fitting::SensorNoise{}.temperature_sigma;
  // Many candidates (a surface's vertices) make the reduced basis on their rows larger than the
  // mesh is worth: the full model then.
  d.settings.full_order = h.names.size() > kCatalogueReducedCandidates;
  CatalogueDetectionInput in = d.settings;
  in.names = h.names;
  for (Eigen::Index c = 0; c < h.positions.rows(); ++c)
    in.points.push_back(h.positions.row(c).transpose());
  d.problem = catalogue_detection(*input.catalogue_mesh, *input.spec, {*input.spec}, in,
                                  input.catalogue_progress)
                  .problem;
  std::vector<int> pool(h.names.size());
  for (std::size_t c = 0; c < pool.size(); ++c) pool[c] = static_cast<int>(c);
  d.greedy = placement::detection_greedy(d.problem, {}, pool, input.m_max, d.bound_sigmas);
  for (const auto& t : result.targets) {
    std::map<std::string, const placement::Selection*> largest;
    for (const auto& s : t.selections) {
      const std::string method(placement::method_name(s.method));
      if (!largest[method] || s.m > largest[method]->m) largest[method] = &s;
    }
    auto& by_method =
        d.kinds_seen.emplace_back(t.target, std::vector<std::pair<std::string, double>>{}).second;
    for (const auto& [method, s] : largest)
      by_method.emplace_back(method, placement::seen_weight(d.problem, s->columns, d.bound_sigmas));
  }
  return d;
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

PlaceReport place_sensors(const PlaceInput& input) {
  PlaceReport report;
  report.histories =
      input.sensor_noise ? with_sensor_noise(input.histories, input.spec->seed) : input.histories;
  placement::PlacementInput in = placement_input(report.histories);
  const auto say = [&](const std::string& line) {
    if (input.progress) input.progress(line);
  };
  if (input.twin) {
    say("placement for estimation: the observer's covariance along the duty cycle (" +
        std::to_string(input.twin->model.states()) + " reduced states)");
    report.estimation.emplace();
    in.estimation =
        estimation_problem(*input.spec, report.histories, *input.twin, *report.estimation);
  }
  const auto t = std::chrono::steady_clock::now();
  say(std::to_string(input.methods.size()) + " methods, m = 1.." + std::to_string(input.m_max) +
      ", " + std::to_string(report.histories.names.size()) + " candidates");
  report.result = placement::place_all(in, placement_options(input));
  if (in.estimation) {
    say("placement for detection: the observer's unknown inputs");
    report.detection = detection_report(input, *in.estimation, *report.estimation, report.result);
  }
  if (input.catalogue_mesh) {
    say("placement for detection: the calibration catalogue's effects");
    report.catalogue_detection = catalogue_detection_report(input, report.histories, report.result);
  }
  report.place_s = core::seconds_since(t);
  return report;
}

}  // namespace tt::studies
