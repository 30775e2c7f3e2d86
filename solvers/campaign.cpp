#include "solvers/campaign.hpp"

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "core/limits.hpp"
#include "core/rng.hpp"
#include "solvers/elastic.hpp"
#include "solvers/loads.hpp"
#include "solvers/thermal_error.hpp"
#include "solvers/twin.hpp"

namespace tt::solvers {
namespace {

using Segment = core::DutyCycle::Segment;

/// A feed-axis program that follows the spindle: while it runs, the axis reciprocates over the
/// base case's first stroke at that stroke's feed scaled by n / n_base (a constant feed per tooth);
/// while it stands, the axis stands where the base case's first standing segment puts it.
std::vector<core::FeedAxis::Segment> feed_following(const core::CaseSpec& base,
                                                    const std::vector<Segment>& spindle) {
  const auto& segs = base.feed_axis.segments;
  const auto stroke = std::find_if(segs.begin(), segs.end(),
                                   [](const auto& s) { return s.feed > 0 && s.from != s.to; });
  const auto rest = std::find_if(segs.begin(), segs.end(),
                                 [](const auto& s) { return s.feed <= 0 || s.from == s.to; });
  const double park = rest != segs.end() ? rest->from : stroke->from;
  const double n_base = speed_at(base.duty_cycle, stroke->start);
  std::vector<core::FeedAxis::Segment> out;
  for (const auto& s : spindle) {
    if (s.speed_rpm > 0)
      out.push_back({s.start, stroke->from, stroke->to,
                     stroke->feed * (n_base > 0 ? s.speed_rpm / n_base : 1.0)});
    else
      out.push_back({s.start, park, park, 0.0});
  }
  return out;
}

core::CaseSpec with_cycle(const core::CaseSpec& base, std::vector<Segment> segments, double end) {
  core::CaseSpec s = base;
  const auto& feed = base.feed_axis.segments;
  if (std::any_of(feed.begin(), feed.end(),
                  [](const auto& f) { return f.feed > 0 && f.from != f.to; }))
    s.feed_axis.segments = feed_following(base, segments);
  s.duty_cycle.segments = std::move(segments);
  s.duty_cycle.end = end;
  return s;
}

/// Every sink that follows the base's initial (ambient) temperature now follows `table`.
void set_ambient(core::CaseSpec& s, double initial_c, const core::TimeTable& table) {
  const double ambient = s.thermal.initial_temperature_c;
  for (auto& c : s.thermal.convection)
    if (c.sink.value.size() == 1 && c.sink.value[0] == ambient) c.sink = table;
  s.thermal.initial_temperature_c = initial_c;
}

std::vector<Segment> irregular_cycle(double end, std::uint64_t seed,
                                     const std::vector<double>& speeds) {
  auto gen = core::generator(seed, 0);
  std::uniform_real_distribution<double> on_minutes(10, 50), off_minutes(5, 25);
  std::uniform_int_distribution<size_t> pick(0, speeds.size() - 1);
  std::vector<Segment> segs;
  double t = 0;
  bool on = true;
  while (t < end) {
    // Whole minutes, so that switches fall on the 60 s output grid of a measurement.
    const double minutes = std::round(on ? on_minutes(gen) : off_minutes(gen));
    segs.push_back({t, on ? speeds[pick(gen)] : 0.0});
    t += 60 * minutes;
    on = !on;
  }
  return segs;
}

}  // namespace

std::vector<CampaignRun> campaign_runs(const core::CaseSpec& base, double hours,
                                       std::uint64_t seed) {
  if (!(hours > 0) || !std::isfinite(hours))
    throw core::CaseError("campaign length (fit --hours) " + std::to_string(hours) +
                          " h: must be a finite number > 0");
  const double end = 3600 * hours;
  if (end / base.thermal.step > static_cast<double>(core::limits::kTimeSteps))
    throw core::CaseError("campaign length (fit --hours) " + std::to_string(hours) +
                          " h: each run would need " + std::to_string(end / base.thermal.step) +
                          " time steps of thermal.step_s = " + std::to_string(base.thermal.step) +
                          " s, more than the limit of " + std::to_string(core::limits::kTimeSteps) +
                          "; shorten the runs or lengthen step_s");
  const double q = end / 4;
  const double t0 = base.thermal.initial_temperature_c;
  std::vector<CampaignRun> runs;
  runs.push_back(
      {"p1_extended", "P-1 then running",
       with_cycle(base, {{0, 3000}, {600, 0}, {900, 3000}, {2100, 0}, {2400, 3000}}, end)});
  runs.push_back({"staircase_up", "speed staircase",
                  with_cycle(base, {{0, 1000}, {q, 2000}, {2 * q, 3000}, {3 * q, 4000}}, end)});
  runs.push_back({"staircase_down", "speed staircase",
                  with_cycle(base, {{0, 4500}, {q, 3000}, {2 * q, 1500}, {3 * q, 0}}, end)});
  runs.push_back(
      {"irregular_a", "irregular on/off",
       with_cycle(base, irregular_cycle(end, core::derived_seed(seed, 1), {1500, 2500, 3500}),
                  end)});
  runs.push_back(
      {"irregular_b", "irregular on/off",
       with_cycle(base, irregular_cycle(end, core::derived_seed(seed, 2), {2000, 3000, 4500}),
                  end)});
  {
    CampaignRun r{"warm_start", "warmer ambient",
                  with_cycle(base, {{0, 2500}, {2 * q, 0}, {2.5 * q, 2500}}, end)};
    set_ambient(r.spec, t0 + 4, core::TimeTable{{0.0}, {t0 + 4}});
    runs.push_back(std::move(r));
  }
  {
    CampaignRun r{"ambient_drift", "ambient drifting",
                  with_cycle(base, {{0, 3000}, {1.5 * q, 0}, {2 * q, 3000}, {3.5 * q, 0}}, end)};
    set_ambient(r.spec, t0, core::TimeTable{{0.0, end / 2, end}, {t0, t0 + 3, t0 + 1.5}});
    runs.push_back(std::move(r));
  }
  runs.push_back(
      {"run_then_cool", "run then cool down", with_cycle(base, {{0, 3500}, {2 * q, 0}}, end)});
  runs.push_back(
      {"mixed_speeds", "mixed speeds",
       with_cycle(base, {{0, 2000}, {3600, 0}, {5400, 4000}, {9000, 0}, {10800, 3000}}, end)});
  return runs;
}

std::vector<CampaignRun> validation_runs(const core::CaseSpec& base, std::uint64_t seed) {
  std::vector<CampaignRun> runs;
  runs.push_back({"own_cycle", "the case's own duty cycle", base});
  runs.push_back(
      {"staircase_6h", "speed staircase 1000-2000-4000-6000-3000-0 rpm",
       with_cycle(base,
                  {{0, 1000}, {3600, 2000}, {7200, 4000}, {10800, 6000}, {14400, 3000}, {18000, 0}},
                  6 * 3600.0)});
  // Draw until the cycle switches at least 15 times (each draw switches about 20 times in 8 h).
  const double end = 8 * 3600.0;
  std::vector<Segment> irregular;
  for (std::uint64_t k = 0; irregular.size() < 16; ++k)
    irregular = irregular_cycle(end, core::derived_seed(seed, 100 + k), {1000, 2500, 4000, 5500});
  runs.push_back({"irregular_8h", "irregular on/off, 8 h", with_cycle(base, irregular, end)});
  return runs;
}

std::vector<CampaignResult> simulate_campaign(const mesh::TetMesh& mesh, const core::CaseSpec& base,
                                              const std::vector<CampaignRun>& runs,
                                              const Progress& progress,
                                              const std::vector<int>& sampled_nodes) {
  const FullThermalSystem ops = thermal_system(mesh, base);
  const ElasticModel elastic(mesh, base);
  // Influence rows of the TCP, the probe points and the feed-axis points in one block solve.
  const TwinOutputs outputs = full_outputs(mesh, base, &elastic);
  std::vector<CampaignResult> results;
  double done = 0, total = 0;
  for (const auto& r : runs) total += r.spec.duty_cycle.end;
  for (const auto& r : runs) {
    const ThermalHistory th = thermal_history(mesh, r.spec, ops, [&](double t, double) {
      if (progress) progress(done + t, total);
    });
    done += r.spec.duty_cycle.end;
    results.push_back(campaign_result(
        outputs, r, th.times, output_history(outputs, outputs.rows * th.temperature, ops.uniform),
        nodal_history(th, sampled_nodes)));
  }
  return results;
}

}  // namespace tt::solvers
