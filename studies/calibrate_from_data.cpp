#include "studies/calibrate_from_data.hpp"

#include <cmath>
#include <limits>

#include "core/errors.hpp"

namespace tt::studies {
namespace {

double correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::VectorXd x = a.array() - a.mean(), y = b.array() - b.mean();
  const double d = x.norm() * y.norm();
  return d > 0 ? x.dot(y) / d : 0.0;
}

/// Residual [m] of a model on each segment, stacked.
Eigen::VectorXd stacked_residual(const fitting::TermModel& m,
                                 const std::vector<fitting::Segment>& segments) {
  Eigen::Index n = 0;
  for (const auto& s : segments) n += s.group.time.size();
  Eigen::VectorXd r(n);
  Eigen::Index at = 0;
  for (const auto& s : segments) {
    const Eigen::Index k = s.group.time.size();
    r.segment(at, k) = s.group.error.col(m.target) - fitting::term_prediction(m, s);
    at += k;
  }
  return r;
}

/// The test segments laid end to end: time on one axis (each segment 1 s after the previous
/// one's end) [s], time since the segment's start [s], speed [rpm] and temperature rises [K].
struct TestAxes {
  Eigen::VectorXd time, since, speed;
  Eigen::MatrixXd rises;
};

TestAxes test_axes(const std::vector<fitting::Segment>& testing) {
  Eigen::Index n = 0;
  for (const auto& s : testing) n += s.group.time.size();
  const Eigen::Index sensors = testing.empty() ? 0 : testing.front().group.temperature.cols();
  TestAxes a{Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n),
             Eigen::MatrixXd(n, sensors)};
  Eigen::Index at = 0;
  double offset = 0;
  for (const auto& s : testing) {
    const Eigen::Index k = s.group.time.size();
    a.speed.segment(at, k) = s.speed;
    a.since.segment(at, k) = s.group.time.array() - s.group.time(0);
    a.time.segment(at, k) = s.group.time.array() - s.group.time(0) + offset;
    offset = a.time(at + k - 1) + 1.0;
    for (Eigen::Index c = 0; c < sensors; ++c)
      a.rises.col(c).segment(at, k) =
          s.group.temperature.col(c).array() - s.group.temperature(0, c);
    at += k;
  }
  return a;
}

ResidualCorrelations correlations(const Eigen::VectorXd& residual, const TestAxes& axes,
                                  bool has_speed, bool with_temperatures) {
  ResidualCorrelations c;
  c.time_since_segment_start = correlation(residual, axes.since);
  c.speed =
      has_speed ? correlation(residual, axes.speed) : std::numeric_limits<double>::quiet_NaN();
  if (with_temperatures) {
    c.temperature_rises.resize(axes.rises.cols());
    for (Eigen::Index k = 0; k < axes.rises.cols(); ++k)
      c.temperature_rises(k) = correlation(residual, axes.rises.col(k));
  }
  return c;
}

/// One channel: the baseline fit --data chooses, the residual study from it, the test figures.
ChannelCalibration channel_calibration(const DataCalibrationInput& in,
                                       const std::vector<fitting::Segment>& training,
                                       const std::vector<fitting::Group>& groups,
                                       const std::vector<fitting::Candidate>& candidates,
                                       const TestAxes& axes, int target) {
  std::vector<int> pool;
  for (std::size_t i = 0; i < groups.size(); ++i) pool.push_back(static_cast<int>(i));
  fitting::ResidualStudyOptions options;
  options.ambient_sensor = in.ambient_sensor;
  ChannelCalibration ch;
  ch.name = training.front().group.target_names[static_cast<std::size_t>(target)];
  ch.choice = fitting::blocked_evaluation(groups, pool, {}, target, candidates);
  ch.study =
      fitting::residual_study(training, target, fitting::baseline_of(ch.choice.model), options);
  ch.before = stacked_residual(ch.study.before, in.testing);
  ch.after = stacked_residual(ch.study.after, in.testing);
  ch.figures_before = core::error_figures(ch.before);
  ch.figures_after = core::error_figures(ch.after);
  // The test RMS as effects are added, in the order the study added them.
  std::vector<fitting::EffectTerm> prefix;
  for (const auto& effect : ch.study.effects) {
    prefix.push_back(effect.term);
    const auto model =
        fitting::fitted_term_model(training, target, ch.study.before.baseline, prefix);
    ch.test_rms_with_effects_so_far.push_back(
        core::error_figures(stacked_residual(model, in.testing)).rms);
  }
  ch.correlations_before = correlations(ch.before, axes, in.has_speed, false);
  ch.correlations_after = correlations(ch.after, axes, in.has_speed, true);
  Eigen::VectorXd measured(ch.before.size());
  Eigen::Index at = 0;
  for (const auto& s : in.testing) {
    measured.segment(at, s.group.time.size()) = s.group.error.col(target);
    at += s.group.time.size();
  }
  ch.test_table.resize(measured.size(), 4);
  ch.test_table << axes.time, axes.speed, measured, measured - ch.before;
  return ch;
}

}  // namespace

DataCalibrationReport calibrate_from_data(const DataCalibrationInput& input,
                                          const Progress& progress) {
  if (input.training_pieces.empty() || input.testing.empty())
    throw core::DataError("calibrate: no training or no test segments");
  const fitting::Blocks blocks = fitting::cross_validation_blocks(input.training_pieces);
  DataCalibrationReport report;
  report.training = blocks.segments;
  report.block_origin =
      (input.has_speed ? "speed cycles; " : "whole runs (no speed input, so no speed cycles); ") +
      blocks.origin;
  report.test_segments = input.testing.size();
  report.has_speed = input.has_speed;
  report.sensor_names = report.training.front().group.sensor_names;
  if (progress)
    progress(std::to_string(report.training.size()) + " training blocks (" + report.block_origin +
             "), " + std::to_string(report.test_segments) + " test segments");
  const std::vector<fitting::Group> groups = fitting::segment_groups(report.training);
  const auto candidates = fitting::measured_data_candidates(
      static_cast<int>(report.sensor_names.size()), input.has_speed, false);
  const TestAxes axes = test_axes(input.testing);
  const auto& targets = report.training.front().group.target_names;
  double sum_before = 0, sum_after = 0;
  Eigen::Index count = 0;
  for (int target = 0; target < static_cast<int>(targets.size()); ++target) {
    if (progress) progress("channel " + targets[static_cast<std::size_t>(target)]);
    report.channels.push_back(
        channel_calibration(input, report.training, groups, candidates, axes, target));
    sum_before += report.channels.back().before.squaredNorm();
    sum_after += report.channels.back().after.squaredNorm();
    count += report.channels.back().before.size();
  }
  report.rms_before = std::sqrt(sum_before / static_cast<double>(count));
  report.rms_after = std::sqrt(sum_after / static_cast<double>(count));
  return report;
}

}  // namespace tt::studies
