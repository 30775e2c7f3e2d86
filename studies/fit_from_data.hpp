// fit --data's pipeline: thermal-error models fitted on measured runs with no machine model behind
// them (DB3401/T 326-2024 metrics S, S_M, S_sigma, and the error on held-out data). SI units
// throughout ([m], [s], [K], [rpm]); io/fit_data_out turns the report into fit.json, summary.md,
// compensation.csv and window_<channel>.csv/.png.
// 1. The training pieces as cross-validation blocks (fitting::cross_validation_blocks: cut into
//    time blocks of equal duration when they are fewer than 4).
// 2. Candidates: fitting::measured_data_candidates (which calibrate without --case chooses among
//    too); with the network, also the network on the grey relational grade's sensors, on the
//    chosen linear model's inputs and on the best ridge's.
// 3. Per displacement channel, blocked cross-validation (each block held out in turn) chooses the
//    lowest mean held-out S², guarded by one standard error against no compensation
//    (fitting::blocked_evaluation); the choice is refitted on all blocks and tested on the test
//    segments, beside the uncompensated drift. Test inputs outside the training range are flagged.
// 4. With a window inside a run, the error on the window continuously: the chosen form refitted on
//    the whole run outside the window, temperatures from the run's start.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/error_figures.hpp"
#include "fitting/segments.hpp"
#include "fitting/selection.hpp"
#include "studies/network_candidate.hpp"

namespace tt::studies {

struct DataFitInput {
  /// speed cycles (or whole runs without a speed), each re-zeroed at its first reading
  std::vector<fitting::Segment> training_pieces;
  /// the held-out data, each segment re-zeroed at its first reading
  std::vector<fitting::Segment> testing;
  /// the run the test window [test_from_s, test_to_s) lies inside, whole, when rows of it lie
  /// outside the window: the continuous figure refits on them
  std::optional<fitting::Segment> windowed_run;
  double test_from_s = -std::numeric_limits<double>::infinity();
  double test_to_s = std::numeric_limits<double>::infinity();
  /// how many runs the training pieces come from (for the blocks' description)
  std::size_t training_runs = 0;
  bool has_speed = false;
  /// a coarser grid of ridge strengths
  bool quick = false;
  /// also try the CNN-BiGRU-attention network (seed 004)
  bool network = false;
};

/// The chosen form refitted on the windowed run outside the window, on the window's rows:
/// #window rows time [s], measured and predicted drift [m].
struct WindowPrediction {
  Eigen::VectorXd time, measured, predicted;
};

/// The network's own figures beside the chosen model's, on the same test segments.
struct DataFitNetwork {
  NetworkFigures figures;
  /// its residual over the test segments, re-zeroed at each one's start [m]
  core::ErrorFigures test;
  /// its mean |error| on the window, refitted continuously [m]; with a windowed run only
  std::optional<double> window_mae_continuous;
};

struct DataFitChannel {
  /// the blocked choice, refitted on every block and tested on the test segments
  fitting::Evaluation evaluation;
  /// the choice's residual and the drift itself over the test segments [m]
  core::ErrorFigures test, uncompensated;
  std::optional<WindowPrediction> window;
  std::optional<DataFitNetwork> network;
};

struct DataFitReport {
  /// the training blocks, then the test segments
  std::vector<fitting::Segment> segments;
  /// how many of `segments` are training blocks
  std::size_t blocks = 0;
  /// how the blocks were made, in words
  std::string block_origin;
  std::vector<fitting::OutOfRange> out_of_range;
  /// per displacement channel, in the runs' order (filled as the study goes)
  std::vector<DataFitChannel> channels;
  std::size_t channel_count = 0;

  /// the test segments' groups
  std::vector<fitting::Group> test_groups() const;
};

/// Called once the blocks are cut (no channel yet) and after each channel.
using DataFitProgress = std::function<void(const DataFitReport&)>;

/// The study. Throws core::DataError when the pieces cannot be cut into blocks or disagree in
/// their sensors and channels.
DataFitReport fit_from_data(const DataFitInput& input, const DataFitProgress& progress = {});

}  // namespace tt::studies
