// A measured run as the fitting library takes it: segments cut at the run's speed cycles, each a
// group of temperatures [K] and re-zeroed displacements [m] with the speed beside it.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "fitting/segments.hpp"
#include "io/measured_data.hpp"

namespace tt::io {

/// #samples spindle speed [rpm]: the input "speed_rpm", else the first input with the unit rpm;
/// empty when the run has no input (then there are no speed cycles and no speed term).
Eigen::VectorXd measured_speed(const MeasuredRun& run);

/// The run's rows with from_s <= time < to_s cut at its speed cycles (fitting::speed_cycles),
/// named "<name>.c<k>_<speed>rpm" after the first nonzero speed of each cycle; targets are the
/// displacement ids, sensors the sensor ids. Rows with a missing reading are dropped per segment.
/// A run with no speed gives one segment, "<name>.whole".
std::vector<fitting::Segment> measured_segments(
    const MeasuredRun& run, const std::string& name,
    double from_s = -std::numeric_limits<double>::infinity(),
    double to_s = std::numeric_limits<double>::infinity());

/// Where one run's rows went: its role, the time it was split at (when it is both a training
/// and a test run) and its segments.
struct RunSplit {
  struct Span {
    std::string name;
    double from_s = 0.0, to_s = 0.0;
    int dropped_rows = 0;
  };
  std::filesystem::path folder;
  bool train = true;
  std::optional<double> split_s;
  std::vector<Span> segments;
};

/// Training runs and test runs read and cut into segments (measured_segments), named
/// "run<k>.train" and "run<k>.test". A run given in both lists is split in time: training rows
/// before `split_s`, test rows from it (default: fitting::held_out_start at 70 % of the run).
struct SplitRuns {
  std::vector<fitting::Segment> training, testing;
  bool has_speed = false;
  /// temperature column of the first run's ambient sensor, -1 when it names none
  int ambient_sensor = -1;
  std::vector<RunSplit> runs;
};

/// Throws core::DataError naming the folder when a list is empty or names a run twice, a run
/// cannot be read, or the runs differ in having a speed input.
SplitRuns read_split_runs(const std::vector<std::filesystem::path>& train,
                          const std::vector<std::filesystem::path>& test,
                          std::optional<double> split_s);

}  // namespace tt::io
