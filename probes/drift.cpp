#include "probes/drift.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.hpp"

namespace tt::probes {

double arc_mean(const Eigen::MatrixXd& samples, int column, double offset, Eigen::Index count) {
  const auto n = samples.rows();
  if (offset < 0.0 || count < 1 ||
      offset + static_cast<double>(count - 1) > static_cast<double>(n - 1))
    throw core::DataError("arc_mean: offset " + std::to_string(offset) + " and " +
                          std::to_string(count) + " samples leave the reading of " +
                          std::to_string(n) + " samples");
  const auto k0 = static_cast<Eigen::Index>(std::floor(offset));
  const double f = offset - static_cast<double>(k0);
  double sum = 0.0;
  for (Eigen::Index j = 0; j < count; ++j) {
    const Eigen::Index k = k0 + j;
    const double next = k + 1 < n ? samples(k + 1, column) : samples(k, column);
    sum += (1.0 - f) * samples(k, column) + f * next;
  }
  return sum / static_cast<double>(count);
}

Eigen::MatrixXd reference_levels(const ProbeRecord& record, const AlignmentPlan& plan,
                                 const std::vector<ReadingAlignment>& alignment,
                                 AlignmentMethod method) {
  const auto readings = static_cast<Eigen::Index>(record.readings.size());
  if (alignment.size() != record.readings.size())
    throw core::DataError("reference_levels: " + std::to_string(alignment.size()) +
                          " alignments for " + std::to_string(readings) + " readings");
  const auto probes = readings > 0 ? record.readings.front().samples_m.cols() : 0;
  Eigen::MatrixXd levels(readings, probes);
  for (Eigen::Index i = 0; i < readings; ++i) {
    const Eigen::MatrixXd& s = record.readings[static_cast<std::size_t>(i)].samples_m;
    if (method == AlignmentMethod::revolution_mean) {
      // Whole revolutions only, so that every harmonic of the runout averages out.
      const double turns = std::floor(static_cast<double>(s.rows()) / plan.samples_per_revolution);
      const auto count =
          std::clamp<Eigen::Index>(std::lround(turns * plan.samples_per_revolution), 1, s.rows());
      levels.row(i) = s.topRows(count).colwise().mean();
      continue;
    }
    const double offset = alignment[static_cast<std::size_t>(i)].offset_samples;
    const auto rows = static_cast<Eigen::Index>(std::ceil(offset)) + plan.level_samples + 1;
    const Eigen::MatrixXd extended = periodic_extension(s, plan.samples_per_revolution, rows);
    for (Eigen::Index p = 0; p < probes; ++p)
      levels(i, p) = arc_mean(extended, static_cast<int>(p), offset, plan.level_samples);
  }
  return levels;
}

DriftSeries drift_from_levels(const Eigen::MatrixXd& levels, const std::vector<double>& times_s,
                              double probe_distance_m) {
  if (static_cast<std::size_t>(levels.rows()) != times_s.size() ||
      levels.cols() < radial_probe_count)
    throw core::DataError("drift_from_levels: " + std::to_string(levels.rows()) + " x " +
                          std::to_string(levels.cols()) + " levels for " +
                          std::to_string(times_s.size()) +
                          " times; need one row per time and at least 4 probe columns");
  if (!(probe_distance_m > 0.0))
    throw core::DataError("probe distance D = " + std::to_string(probe_distance_m) +
                          " m: must be > 0");
  DriftSeries out;
  out.has_axial = levels.cols() > radial_probe_count;
  for (Eigen::Index i = 0; i < levels.rows(); ++i) {
    const Eigen::RowVectorXd d = levels.row(i) - levels.row(0);
    DriftPoint p;
    p.time_s = times_s[static_cast<std::size_t>(i)];
    p.drift.y1_m = d(s1_y1);
    p.drift.y2_m = d(s2_y2);
    p.drift.x1_m = d(s3_x1);
    p.drift.x2_m = d(s4_x2);
    p.drift.z_m = out.has_axial ? d(s5_z) : 0.0;
    p.tilt_x_rad = std::atan((d(s4_x2) - d(s3_x1)) / probe_distance_m);
    p.tilt_y_rad = std::atan((d(s2_y2) - d(s1_y1)) / probe_distance_m);
    out.points.push_back(p);
  }
  return out;
}

RecoveredDrift recovered_drift(const ProbeRecord& record, const AlignmentOptions& options,
                               AlignmentMethod method) {
  RecoveredDrift out;
  out.method = method;
  out.plan = alignment_plan(record, options);
  out.alignment = record_alignment(record, out.plan, method);
  std::vector<double> times;
  for (const Reading& r : record.readings) times.push_back(r.start_time_s);
  out.drift = drift_from_levels(reference_levels(record, out.plan, out.alignment, method), times,
                                record.probe_distance_m);
  return out;
}

DriftError drift_error(const DriftSeries& estimate, const DriftSeries& truth) {
  if (estimate.points.size() != truth.points.size())
    throw core::DataError("drift_error: " + std::to_string(estimate.points.size()) +
                          " estimated readings against " + std::to_string(truth.points.size()) +
                          " true ones; the truth must have one row per reading");
  DriftError e;
  const bool axial = estimate.has_axial && truth.has_axial;
  for (std::size_t i = 0; i < truth.points.size(); ++i) {
    const DriftState& a = estimate.points[i].drift;
    const DriftState& b = truth.points[i].drift;
    for (double d : {a.x1_m - b.x1_m, a.y1_m - b.y1_m, a.x2_m - b.x2_m, a.y2_m - b.y2_m,
                     axial ? a.z_m - b.z_m : 0.0})
      e.max_drift_m = std::max(e.max_drift_m, std::abs(d));
    e.max_tilt_rad = std::max(
        {e.max_tilt_rad, std::abs(estimate.points[i].tilt_x_rad - truth.points[i].tilt_x_rad),
         std::abs(estimate.points[i].tilt_y_rad - truth.points[i].tilt_y_rad)});
  }
  return e;
}

}  // namespace tt::probes
