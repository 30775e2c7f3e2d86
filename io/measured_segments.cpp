#include "io/measured_segments.hpp"

#include <cmath>

#include "core/errors.hpp"

namespace tt::io {

Eigen::VectorXd measured_speed(const MeasuredRun& run) {
  const Eigen::Index n = run.time.size();
  int column = -1;
  for (std::size_t i = 0; i < run.inputs.size(); ++i)
    if (run.inputs[i] == "speed_rpm") column = static_cast<int>(i);
  if (column < 0 && !run.inputs.empty()) column = 0;  // every input of this format is in rpm
  if (column < 0) return Eigen::VectorXd();
  if (run.input_values.rows() != n)
    throw core::DataError(run.folder.string() + ": " + std::to_string(run.input_values.rows()) +
                          " input rows for " + std::to_string(n) + " samples");
  return run.input_values.col(column);
}

std::vector<fitting::Segment> measured_segments(const MeasuredRun& run, const std::string& name,
                                                double from_s, double to_s) {
  Eigen::Index begin = 0, end = run.time.size();
  while (begin < end && run.time(begin) < from_s) ++begin;
  while (end > begin && run.time(end - 1) >= to_s) --end;
  if (end - begin < 2)
    throw core::DataError(run.folder.string() + ": " + std::to_string(end - begin) +
                          " samples in [" + std::to_string(from_s) + ", " + std::to_string(to_s) +
                          ") s: expected at least 2");
  const Eigen::VectorXd speed_all = measured_speed(run);
  const Eigen::VectorXd time = run.time.segment(begin, end - begin);
  const Eigen::VectorXd speed =
      speed_all.size() ? Eigen::VectorXd(speed_all.segment(begin, end - begin)) : speed_all;
  const Eigen::MatrixXd temperature = run.temperature.middleRows(begin, end - begin);
  const Eigen::MatrixXd displacement = run.displacement.middleRows(begin, end - begin);
  // A missing speed reading does not start a cycle: hold the last one for the cutting only.
  Eigen::VectorXd held = speed;
  for (Eigen::Index i = 0; i < held.size(); ++i)
    if (!std::isfinite(held(i))) held(i) = i > 0 ? held(i - 1) : 0.0;
  std::vector<std::string> sensors, targets;
  for (const auto& s : run.sensors) sensors.push_back(s.id);
  for (const auto& p : run.displacements) targets.push_back(p.id);
  std::vector<fitting::Segment> segments;
  if (speed.size() == 0) {
    // No speed, so no cycles: the window's rows are one piece (fitting::cross_validation_blocks
    // cuts it into time blocks when the pieces are too few).
    segments.push_back(fitting::segment_of(name + ".whole", time, speed, temperature, displacement,
                                           sensors, targets, {0, time.size()}));
    return segments;
  }
  int k = 0;
  for (const auto& range : fitting::speed_cycles(held)) {
    double first = 0.0;
    for (Eigen::Index i = range.begin; i < range.end && first == 0.0; ++i) first = held(i);
    const std::string label = name + ".c" + std::to_string(++k) + "_" +
                              std::to_string(static_cast<long>(std::lround(first))) + "rpm";
    segments.push_back(fitting::segment_of(label, time, speed, temperature, displacement, sensors,
                                           targets, range));
  }
  return segments;
}

}  // namespace tt::io
