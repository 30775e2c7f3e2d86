// Virtual probe signals: a spindle turning at the measuring speed with a runout and form-error
// profile, drifting thermally, read by four radial probes (and optionally an axial one) with
// noise. Each reading starts at a random, continuous spindle angle, as on a spindle without
// orientation.
#pragma once

#include <cstdint>
#include <vector>

#include "probes/record.hpp"

namespace tt::probes {

/// One term a·cos(n·θ + ψ) of a profile in the spindle's own angle θ; order 1 is eccentricity.
struct Harmonic {
  int order = 1;
  double amplitude_m = 0.0;
  double phase_rad = 0.0;
};

struct VirtualProbeSetup {
  double speed_rpm = 3000.0;
  double sample_rate_hz = 10000.0;
  /// Length of every reading in spindle revolutions; must exceed 1.
  double revolutions_per_reading = 2.5;
  /// Axial distance D between the probe planes [m]
  double probe_distance_m = 0.15;
  /// Radial runout and form error at plane 1 (probes 1, 3) and plane 2 (probes 2, 4)
  std::vector<Harmonic> runout_plane1;
  std::vector<Harmonic> runout_plane2;
  /// Face runout seen by the axial probe
  std::vector<Harmonic> runout_axial;
  bool axial_probe = false;
  /// Standard deviation of white probe noise [m]
  double noise_std_m = 0.1e-6;
  std::uint64_t seed = 1;
};

/// Eccentricity of `eccentricity_m` at phase `phase_rad` plus 2nd, 3rd and 5th harmonic form
/// errors of 20 %, 12 % and 6 % of it: a plausible ground spindle nose.
std::vector<Harmonic> spindle_runout(double eccentricity_m, double phase_rad);

/// Profile value Σ a·cos(n·θ + ψ) at spindle angle θ [m].
double profile_value(const std::vector<Harmonic>& profile, double angle_rad);

/// A record whose readings are taken at the history's times and its true start angles.
struct VirtualRecord {
  ProbeRecord record;
  /// Spindle angle at the first sample of each reading [rad], in [0, 2π)
  std::vector<double> start_angle_rad;
};

/// Virtual readings, one per history sample; the drift is constant within a reading (a reading
/// lasts a fraction of a second, thermal drift takes minutes). Seeded per reading from
/// setup.seed, so reading i does not depend on how many readings are made.
VirtualRecord virtual_record(const VirtualProbeSetup& setup, const DriftHistory& history);

/// Drift relative to the first history sample, with the tilts of formulas (3) and (4).
DriftSeries drift_relative_to_first(const DriftHistory& history, double probe_distance_m,
                                    bool has_axial);

}  // namespace tt::probes
