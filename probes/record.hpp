// Values shared by the probe library: raw readings of the four (or five) probes and drift series.
// Probe order everywhere: S1 = Y at plane 1, S2 = Y at plane 2, S3 = X at plane 1, S4 = X at
// plane 2, S5 = axial (Z) probe when present. Plane 2 lies a distance D further along the axis.
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace tt::probes {

/// Columns of Reading::samples_m.
enum ProbeColumn : int { s1_y1 = 0, s2_y2 = 1, s3_x1 = 2, s4_x2 = 3, s5_z = 4 };
inline constexpr int radial_probe_count = 4;

/// One reading: every probe sampled at a fixed rate while the spindle turns at the measuring
/// speed for more than one revolution, starting at an unknown angle.
struct Reading {
  double start_time_s = 0.0;
  /// #samples x #probes (4, or 5 with the axial probe) displacements [m]
  Eigen::MatrixXd samples_m;
};

/// All readings of one measuring run and the constants needed to interpret them.
struct ProbeRecord {
  double speed_rev_per_s = 0.0;
  double sample_rate_hz = 0.0;
  /// Axial distance D between the probe planes [m]
  double probe_distance_m = 0.0;
  std::vector<Reading> readings;

  bool has_axial_probe() const {
    return !readings.empty() && readings.front().samples_m.cols() > radial_probe_count;
  }
  /// Samples per spindle revolution; in general not a whole number.
  double samples_per_revolution() const { return sample_rate_hz / speed_rev_per_s; }
};

/// Displacement of the spindle at the two probe planes and along its axis [m].
struct DriftState {
  double x1_m = 0.0;
  double y1_m = 0.0;
  double x2_m = 0.0;
  double y2_m = 0.0;
  double z_m = 0.0;
};

/// The spindle's thermal drift at one time; a history feeds the virtual probes.
struct DriftSample {
  double time_s = 0.0;
  DriftState drift;
};
using DriftHistory = std::vector<DriftSample>;

/// Drift and tilt at one reading, relative to the first reading.
struct DriftPoint {
  double time_s = 0.0;
  DriftState drift;
  double tilt_x_rad = 0.0;
  double tilt_y_rad = 0.0;
};

struct DriftSeries {
  std::vector<DriftPoint> points;
  bool has_axial = false;
};

}  // namespace tt::probes
