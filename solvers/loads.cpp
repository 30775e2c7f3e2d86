#include "solvers/loads.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>

#include "core/errors.hpp"
#include "core/limits.hpp"

namespace tt::solvers {

double speed_at(const core::DutyCycle& cycle, double t) {
  double n = cycle.segments.empty() ? 0.0 : cycle.segments.front().speed_rpm;
  for (const auto& s : cycle.segments)
    if (s.start <= t) n = s.speed_rpm;
  return n;
}

double source_power(const core::HeatSource& s, double n) {
  return source_power(s, n, 0.0);
}

double source_power(const core::HeatSource& s, double n, double feed) {
  using Law = core::HeatSource::Law;
  switch (s.law) {
    case Law::constant:
      return s.power_ref;
    case Law::feed_power:
      if (feed <= 0) return 0.0;
      return s.power_ref * std::pow(feed / s.ref_feed, s.exponent);
    case Law::speed_power:
      if (n <= 0) return 0.0;
      return s.power_ref * std::pow(n / s.ref_speed_rpm, s.exponent);
    case Law::palmgren: {
      if (n <= 0) return 0.0;
      // Palmgren's bearing friction torque in N mm with dm in mm, nu in cSt, n in rpm.
      const double dm_mm = s.palmgren_dm * 1e3;
      const double nu_n = s.palmgren_nu_cSt * n;
      const double m0 = nu_n >= 2000
                            ? 1e-7 * s.palmgren_f0 * std::pow(nu_n, 2.0 / 3.0) * std::pow(dm_mm, 3)
                            : 160e-7 * s.palmgren_f0 * std::pow(dm_mm, 3);
      const double m1 = s.palmgren_f1 * s.palmgren_p1 * dm_mm;
      return (m0 + m1) * 1e-3 * 2 * std::numbers::pi * n / 60.0;
    }
  }
  return 0.0;
}

namespace {

/// The feed-axis segment in force at t (a switch at t belongs to the segment that starts there).
const core::FeedAxis::Segment* feed_segment_at(const core::FeedAxis& axis, double t) {
  const core::FeedAxis::Segment* seg = axis.segments.empty() ? nullptr : &axis.segments.front();
  for (const auto& s : axis.segments)
    if (s.start <= t) seg = &s;
  return seg;
}

bool standing(const core::FeedAxis::Segment& s) {
  return s.feed <= 0 || s.from == s.to;
}

}  // namespace

double feed_speed_at(const core::FeedAxis& axis, double t) {
  const auto* s = feed_segment_at(axis, t);
  return s && !standing(*s) ? s->feed : 0.0;
}

double axis_position_at(const core::FeedAxis& axis, double t) {
  const auto* s = feed_segment_at(axis, t);
  if (!s) return 0.0;
  if (standing(*s)) return s->from;
  const double stroke = std::abs(s->to - s->from);
  const double travelled = std::fmod(std::max(0.0, t - s->start) * s->feed, 2 * stroke);
  const double along = travelled <= stroke ? travelled : 2 * stroke - travelled;
  return s->from + (s->to > s->from ? along : -along);
}

double film_coefficient(const core::Convection& c, double n) {
  if (c.h_speed_gain == 0 || n <= 0) return c.h;
  return c.h + c.h_speed_gain * std::pow(n / c.speed_ref_rpm, c.speed_exponent);
}

double table_value(const core::TimeTable& table, double t) {
  if (table.time.empty()) return 0.0;
  if (t <= table.time.front()) return table.value.front();
  if (t >= table.time.back()) return table.value.back();
  const auto it = std::upper_bound(table.time.begin(), table.time.end(), t);
  const size_t i = static_cast<size_t>(it - table.time.begin());
  const double w = (t - table.time[i - 1]) / (table.time[i] - table.time[i - 1]);
  return (1 - w) * table.value[i - 1] + w * table.value[i];
}

std::vector<double> switch_times(const core::CaseSpec& spec) {
  const double end = spec.duty_cycle.end;
  std::vector<double> s;
  for (const auto& seg : spec.duty_cycle.segments)
    if (seg.start > 0 && seg.start < end) s.push_back(seg.start);
  for (const auto& seg : spec.feed_axis.segments)
    if (seg.start > 0 && seg.start < end) s.push_back(seg.start);
  for (const auto& c : spec.thermal.convection)
    if (c.sink.time.size() > 1)
      for (double t : c.sink.time)
        if (t > 0 && t < end) s.push_back(t);
  std::sort(s.begin(), s.end());
  s.erase(std::unique(s.begin(), s.end()), s.end());
  return s;
}

double next_switch(const core::CaseSpec& spec, double t) {
  double next = std::numeric_limits<double>::infinity();
  // Segment starts and table points are ascending: the first after t in each.
  const auto first_after = [&](const auto& list, auto time_of) {
    const auto it = std::upper_bound(list.begin(), list.end(), t,
                                     [&](double v, const auto& e) { return v < time_of(e); });
    if (it != list.end()) next = std::min(next, time_of(*it));
  };
  first_after(spec.duty_cycle.segments, [](const auto& seg) { return seg.start; });
  first_after(spec.feed_axis.segments, [](const auto& seg) { return seg.start; });
  for (const auto& c : spec.thermal.convection)
    if (c.sink.time.size() > 1) first_after(c.sink.time, [](double v) { return v; });
  return next;
}

void extend_duty_cycle(core::DutyCycle& cycle, double t, double speed_rpm) {
  cycle.end = t;
  if (!std::isfinite(speed_rpm)) return;
  const double v = std::max(speed_rpm, 0.0);
  if (cycle.segments.empty())
    cycle.segments.push_back({0.0, v});
  else if (v != cycle.segments.back().speed_rpm)
    cycle.segments.push_back({t, v});
}

void check_first_sample_time(double t, double step) {
  const double steps = t / step;
  if (!(steps > static_cast<double>(core::limits::kTimeSteps))) return;
  char text[400];
  const auto shown = [&text](double v) {
    const auto [end, ec] = std::to_chars(text, text + sizeof text, v, std::chars_format::fixed);
    return ec == std::errc() ? std::string(text, end) : std::to_string(v);
  };
  throw core::DataError("the first sample is at time_s = " + shown(t) +
                        ": the model starts at t = 0 at the machine's initial temperature and "
                        "would march " +
                        std::to_string(static_cast<long long>(steps)) + " steps of " + shown(step) +
                        " s to it (more than " + std::to_string(core::limits::kTimeSteps) +
                        "); a clock's time is not a run's: time_s counts from the run's start");
}

namespace {

/// end / interval as a count, refused beyond `limit` before anything of that size is made.
std::int64_t bounded_count(double end, double interval, std::int64_t limit, const char* key,
                           const char* counted) {
  if (!(interval > 0) || !std::isfinite(interval))
    throw core::SolverError(std::string(key) + " = " + std::to_string(interval) +
                            " s: must be a finite number > 0");
  const double count = std::ceil(end / interval - 1e-9);
  if (!(count <= static_cast<double>(limit)))
    throw core::SolverError(
        std::string(key) + " = " + std::to_string(interval) + " s over " + std::to_string(end) +
        " s would need more than " + std::to_string(limit) + " " + counted +
        " (the limit, core/limits.hpp); lengthen " + key + " or shorten the run");
  return std::max<std::int64_t>(1, static_cast<std::int64_t>(count));
}

}  // namespace

std::vector<double> time_grid(const core::CaseSpec& spec, double max_step) {
  const double end = spec.duty_cycle.end;
  bounded_count(end, max_step, core::limits::kTimeSteps, "thermal.step_s", "time steps");
  std::vector<double> marks = switch_times(spec);
  marks.push_back(end);
  std::vector<double> grid;
  double a = 0;
  for (double b : marks) {
    // Each piece is shorter than the run, so its count is within the limit too.
    const std::int64_t k =
        std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil((b - a) / max_step - 1e-9)));
    for (std::int64_t i = 1; i < k; ++i)
      grid.push_back(a + (b - a) * static_cast<double>(i) / static_cast<double>(k));
    grid.push_back(b);
    a = b;
  }
  return grid;
}

std::vector<double> output_times(const core::CaseSpec& spec) {
  const double end = spec.duty_cycle.end, dt = spec.thermal.output_interval;
  bounded_count(end, dt, core::limits::kOutputTimes, "thermal.output_interval_s", "output times");
  std::vector<double> t;
  for (std::int64_t k = 1; static_cast<double>(k) * dt < end * (1 - 1e-12); ++k)
    t.push_back(static_cast<double>(k) * dt);
  t.push_back(end);
  return t;
}

double heat_delivered(const core::CaseSpec& spec) {
  // Spindle and feed speeds are constant between consecutive switches.
  std::vector<double> marks = switch_times(spec);
  marks.push_back(spec.duty_cycle.end);
  double total = 0, a = 0;
  for (double b : marks) {
    const double mid = 0.5 * (a + b);
    const double n = speed_at(spec.duty_cycle, mid), v = feed_speed_at(spec.feed_axis, mid);
    for (const auto& s : spec.thermal.sources) total += source_power(s, n, v) * (b - a);
    a = b;
  }
  return total;
}

}  // namespace tt::solvers
