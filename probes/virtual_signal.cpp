#include "probes/virtual_signal.hpp"

#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "core/errors.hpp"
#include "core/rng.hpp"

namespace tt::probes {
namespace {

using std::numbers::pi;

// Direction of each probe's axis around the spindle, measured like the spindle angle: a probe
// at direction α sees the surface point at spindle angle θ − α.
constexpr double x_probe_direction_rad = 0.0;
constexpr double y_probe_direction_rad = pi / 2.0;

void check_setup(const VirtualProbeSetup& s, const DriftHistory& history) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw core::DataError("virtual probe setup: " + what);
  };
  require(s.speed_rpm > 0.0, "speed_rpm = " + std::to_string(s.speed_rpm) + ": must be > 0");
  require(s.sample_rate_hz > 0.0,
          "sample_rate_hz = " + std::to_string(s.sample_rate_hz) + ": must be > 0");
  require(s.revolutions_per_reading > 1.0,
          "revolutions_per_reading = " + std::to_string(s.revolutions_per_reading) +
              ": must be > 1 so that every reading contains the reference angle");
  require(s.probe_distance_m > 0.0,
          "probe_distance_m = " + std::to_string(s.probe_distance_m) + ": must be > 0");
  require(s.noise_std_m >= 0.0,
          "noise_std_m = " + std::to_string(s.noise_std_m) + ": must be >= 0");
  require(!history.empty(), "the drift history is empty: give at least one reading time");
  for (std::size_t i = 1; i < history.size(); ++i)
    require(history[i].time_s > history[i - 1].time_s,
            "drift history time " + std::to_string(history[i].time_s) + " s at sample " +
                std::to_string(i) + " is not after the previous one: times must increase");
}

}  // namespace

std::vector<Harmonic> spindle_runout(double eccentricity_m, double phase_rad) {
  return {{1, eccentricity_m, phase_rad},
          {2, 0.20 * eccentricity_m, 0.7 + 2.0 * phase_rad},
          {3, 0.12 * eccentricity_m, 2.1 - phase_rad},
          {5, 0.06 * eccentricity_m, 4.0 + phase_rad}};
}

double profile_value(const std::vector<Harmonic>& profile, double angle_rad) {
  double v = 0.0;
  for (const Harmonic& h : profile)
    v += h.amplitude_m * std::cos(h.order * angle_rad + h.phase_rad);
  return v;
}

VirtualRecord virtual_record(const VirtualProbeSetup& setup, const DriftHistory& history) {
  check_setup(setup, history);
  VirtualRecord out;
  ProbeRecord& rec = out.record;
  rec.speed_rev_per_s = setup.speed_rpm / 60.0;
  rec.sample_rate_hz = setup.sample_rate_hz;
  rec.probe_distance_m = setup.probe_distance_m;
  const double per_rev = rec.samples_per_revolution();
  const auto n = static_cast<Eigen::Index>(std::ceil(setup.revolutions_per_reading * per_rev));
  const int probes = setup.axial_probe ? radial_probe_count + 1 : radial_probe_count;

  for (std::size_t i = 0; i < history.size(); ++i) {
    auto gen = core::generator(setup.seed, i);
    std::uniform_real_distribution<double> start_angle(0.0, 2.0 * pi);
    std::normal_distribution<double> noise(0.0, 1.0);
    const double theta0 = start_angle(gen);
    const DriftState& d = history[i].drift;

    Reading r;
    r.start_time_s = history[i].time_s;
    r.samples_m.resize(n, probes);
    for (Eigen::Index j = 0; j < n; ++j) {
      const double theta = theta0 + 2.0 * pi * static_cast<double>(j) / per_rev;
      r.samples_m(j, s1_y1) =
          d.y1_m + profile_value(setup.runout_plane1, theta - y_probe_direction_rad);
      r.samples_m(j, s2_y2) =
          d.y2_m + profile_value(setup.runout_plane2, theta - y_probe_direction_rad);
      r.samples_m(j, s3_x1) =
          d.x1_m + profile_value(setup.runout_plane1, theta - x_probe_direction_rad);
      r.samples_m(j, s4_x2) =
          d.x2_m + profile_value(setup.runout_plane2, theta - x_probe_direction_rad);
      if (setup.axial_probe)
        r.samples_m(j, s5_z) = d.z_m + profile_value(setup.runout_axial, theta);
      for (int p = 0; p < probes; ++p) r.samples_m(j, p) += setup.noise_std_m * noise(gen);
    }
    rec.readings.push_back(std::move(r));
    out.start_angle_rad.push_back(theta0);
  }
  return out;
}

DriftSeries drift_relative_to_first(const DriftHistory& history, double probe_distance_m,
                                    bool has_axial) {
  DriftSeries out;
  out.has_axial = has_axial;
  if (history.empty()) return out;
  const DriftState& d0 = history.front().drift;
  for (const DriftSample& s : history) {
    DriftPoint p;
    p.time_s = s.time_s;
    p.drift = {s.drift.x1_m - d0.x1_m, s.drift.y1_m - d0.y1_m, s.drift.x2_m - d0.x2_m,
               s.drift.y2_m - d0.y2_m, has_axial ? s.drift.z_m - d0.z_m : 0.0};
    p.tilt_x_rad = std::atan((p.drift.x2_m - p.drift.x1_m) / probe_distance_m);
    p.tilt_y_rad = std::atan((p.drift.y2_m - p.drift.y1_m) / probe_distance_m);
    out.points.push_back(p);
  }
  return out;
}

}  // namespace tt::probes
