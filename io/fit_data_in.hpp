// fit --data's inputs: the measured runs read, checked against each other, and cut into training
// pieces and held-out test segments around the test window (the study: studies/fit_from_data.hpp).
#pragma once

#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "fitting/segments.hpp"
#include "io/measured_data.hpp"

namespace tt::io {

/// The measured runs as fit --data takes them. The held-out data: the runs given as test runs,
/// else a time window (given, or the published figure's), else the last run when there are 3 or
/// more, else the last 30 % of the last run (with a speed: from the start of its last speed cycle
/// that begins by 70 % of it). Every other row trains. Runs are cut at their speed cycles when they
/// have a speed (io::measured_segments), kept whole when not; each piece is re-zeroed.
struct DataFitRuns {
  struct Run {
    std::filesystem::path folder;
    std::string machine, run;
    bool training = true;
  };
  /// the training runs, then the test runs
  std::vector<Run> runs;
  std::size_t training_runs = 0;
  bool has_speed = false;
  /// the last run's published figure (meta.json `published`); none when test runs are given
  std::optional<PublishedFigure> published;
  /// the held-out window [from_s, to_s) of the windowed run (infinite: open), and why it is that
  double from_s = -std::numeric_limits<double>::infinity();
  double to_s = std::numeric_limits<double>::infinity();
  std::string window_origin;
  /// training pieces (named "run<k>" or "run" with the cycle) and test segments (".test")
  std::vector<fitting::Segment> training_pieces, testing;
  /// the run the window lies inside, whole (one segment from its first reading), when the window
  /// leaves rows of it outside: the continuous figure refits on those
  std::optional<fitting::Segment> windowed_run;
};

/// Throws core::DataError naming the run when a run is given twice, as training and test run,
/// cannot be read, has no displacement or temperature columns, or differs from the first in its
/// columns or in having a speed input; when test runs and a window are both given; and when the
/// window holds no samples or leaves no training data.
DataFitRuns read_data_fit_runs(const std::vector<std::filesystem::path>& runs,
                               const std::vector<std::filesystem::path>& test_runs,
                               std::optional<double> test_from_s, std::optional<double> test_to_s);

}  // namespace tt::io
