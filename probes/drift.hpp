// Drift and tilt of the spindle from the probe readings at the reference angle (patent
// CN101628396 formulas (1)–(4)): drift = S_k(i) − S_k(1); Δθ_X = arctan(((S4(i) − S4(1)) −
// (S3(i) − S3(1))) / D); Δθ_Y = arctan(((S2(i) − S2(1)) − (S1(i) − S1(1))) / D).
#pragma once

#include <vector>

#include "probes/alignment.hpp"
#include "probes/record.hpp"

namespace tt::probes {

/// Mean of `count` samples of one probe column starting at fractional sample `offset`, with
/// linear interpolation between samples [m]. Requires offset >= 0 and offset + count − 1 <= n − 1.
double arc_mean(const Eigen::MatrixXd& samples, int column, double offset, Eigen::Index count);

/// #readings x #probes probe values at the reference angle [m]: the arc mean of
/// plan.level_samples samples from each reading's aligned offset; for revolution_mean, the mean
/// over the whole revolutions of the reading instead.
Eigen::MatrixXd reference_levels(const ProbeRecord& record, const AlignmentPlan& plan,
                                 const std::vector<ReadingAlignment>& alignment,
                                 AlignmentMethod method);

/// Formulas (1)–(4) applied to the levels; z from the fifth column when present.
DriftSeries drift_from_levels(const Eigen::MatrixXd& levels, const std::vector<double>& times_s,
                              double probe_distance_m);

/// Everything one recovery produced, kept so that reports can show the alignment.
struct RecoveredDrift {
  AlignmentMethod method = AlignmentMethod::information_distance;
  AlignmentPlan plan;
  std::vector<ReadingAlignment> alignment;
  DriftSeries drift;
};

/// Plan, align, take the levels at the reference angle, and apply formulas (1)–(4).
RecoveredDrift recovered_drift(const ProbeRecord& record, const AlignmentOptions& options,
                               AlignmentMethod method);

/// Largest deviation of `estimate` from `truth` over all readings.
struct DriftError {
  double max_drift_m = 0.0;  ///< over x1, y1, x2, y2 (and z when both have it)
  double max_tilt_rad = 0.0;
};
DriftError drift_error(const DriftSeries& estimate, const DriftSeries& truth);

}  // namespace tt::probes
