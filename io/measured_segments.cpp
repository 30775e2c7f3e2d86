#include "io/measured_segments.hpp"

#include <cmath>
#include <set>

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

namespace {

std::set<std::string> canonical_names(const std::vector<std::filesystem::path>& folders) {
  std::set<std::string> names;
  for (const auto& p : folders) names.insert(std::filesystem::weakly_canonical(p).string());
  return names;
}

}  // namespace

SplitRuns read_split_runs(const std::vector<std::filesystem::path>& train,
                          const std::vector<std::filesystem::path>& test,
                          std::optional<double> split_s) {
  if (train.empty() || test.empty())
    throw core::DataError(
        "calibrate: give --train RUN... and --test RUN... (the same run in both splits it in "
        "time)");
  require_distinct_runs(train, "--train");
  require_distinct_runs(test, "--test");
  const std::set<std::string> train_names = canonical_names(train),
                              test_names = canonical_names(test);
  constexpr double inf = std::numeric_limits<double>::infinity();
  SplitRuns out;
  std::filesystem::path first;
  const auto add = [&](const std::filesystem::path& folder, bool is_train) {
    const std::string key = std::filesystem::weakly_canonical(folder).string();
    const bool shared = train_names.count(key) && test_names.count(key);
    const MeasuredRun run = read_measured_run(folder);
    const Eigen::VectorXd speed = measured_speed(run);
    const bool has_speed = speed.size() != 0;
    if (out.runs.empty()) {
      first = folder;
      out.has_speed = has_speed;
      if (run.ambient_sensor)
        for (std::size_t k = 0; k < run.sensors.size(); ++k)
          if (run.sensors[k].id == *run.ambient_sensor) out.ambient_sensor = static_cast<int>(k);
    } else if (has_speed != out.has_speed) {
      throw core::DataError(folder.string() +
                            (has_speed ? " has a speed input but " : " has none but ") +
                            first.string() + (has_speed ? " has none" : " has one") +
                            ": every run must have the same inputs; hint: drop the speed column "
                            "from all runs, or give it in all");
    }
    const double split =
        shared ? split_s.value_or(fitting::held_out_start(run.time, speed, 0.7, 0.6)) : inf;
    const std::string name =
        "run" + std::to_string(out.runs.size() + 1) + (is_train ? ".train" : ".test");
    auto segments = is_train ? measured_segments(run, name, -inf, shared ? split : inf)
                             : measured_segments(run, name, shared ? split : -inf, inf);
    RunSplit record{folder, is_train, shared ? std::optional<double>(split) : std::nullopt, {}};
    for (const auto& s : segments)
      record.segments.push_back(
          {s.group.name, s.group.time(0), s.group.time(s.group.time.size() - 1), s.dropped_rows});
    out.runs.push_back(std::move(record));
    auto& into = is_train ? out.training : out.testing;
    into.insert(into.end(), segments.begin(), segments.end());
  };
  for (const auto& f : train) add(f, true);
  for (const auto& f : test) add(f, false);
  return out;
}

}  // namespace tt::io
