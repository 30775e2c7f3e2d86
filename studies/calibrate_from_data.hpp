// Calibration from measured data alone (`thermotwin calibrate` without --case): per displacement
// channel, the model fit --data chooses on the training blocks, the terms its residual is traced
// to, and the error on held-out test segments before and after. SI units throughout ([m], [s],
// [rpm], [K]); io/calibration_data_out turns the report into calibration.json, report.md and
// residual_<channel>.csv.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/error_figures.hpp"
#include "fitting/residual_study.hpp"
#include "fitting/segments.hpp"
#include "fitting/selection.hpp"
#include "studies/progress.hpp"
#include "studies/test_figures.hpp"

namespace tt::studies {

/// The measured runs, cut: training pieces (speed cycles or whole runs; fewer than 4 are cut
/// into time blocks by the study) and test segments, each with its drift re-zeroed.
struct DataCalibrationInput {
  std::vector<fitting::Segment> training_pieces;
  std::vector<fitting::Segment> testing;
  /// the runs have a speed input (otherwise no speed term is tried and none is correlated)
  bool has_speed = false;
  /// temperature column of the runs' ambient sensor, -1 when they name none
  int ambient_sensor = -1;
};

/// How a test residual still follows what the data can express (Pearson correlations).
struct ResidualCorrelations {
  double time_since_segment_start = 0.0;
  /// NaN when the runs have no speed
  double speed = 0.0;
  /// per sensor, with its temperature rise since the segment's start (empty for `before`)
  Eigen::VectorXd temperature_rises;
};

/// One displacement channel's calibration.
struct ChannelCalibration {
  std::string name;
  /// the baseline: fit --data's choice on the training blocks
  fitting::Evaluation choice;
  /// the residual study from that baseline (its effects in the order they were claimed)
  fitting::ChannelStudy study;
  /// the test RMS [m] with the first k + 1 claimed effects, per claimed effect
  std::vector<double> test_rms_with_effects_so_far;
  /// the test residuals, stacked over the test segments [m]
  Eigen::VectorXd before, after;
  core::ErrorFigures figures_before, figures_after;
  bool worse_after_than_before() const {
    return studies::worse_after_than_before(figures_before, figures_after);
  }
  ResidualCorrelations correlations_before, correlations_after;
  /// #test samples x 4: time on one axis (segments laid end to end, 1 s apart) [s], speed [rpm]
  /// (zeros without one), measured drift [m], the baseline's prediction [m]
  Eigen::MatrixXd test_table;
};

struct DataCalibrationReport {
  /// the training blocks the study ran on, and how they were cut
  std::vector<fitting::Segment> training;
  std::string block_origin;
  std::size_t test_segments = 0;
  bool has_speed = false;
  std::vector<std::string> sensor_names;
  std::vector<ChannelCalibration> channels;
  /// over every channel and test sample [m]
  double rms_before = 0.0, rms_after = 0.0;
};

/// The study. Throws core::DataError when the training pieces cannot be cut into at least two
/// blocks or the segments disagree in their sensors and channels.
DataCalibrationReport calibrate_from_data(const DataCalibrationInput& input,
                                          const Progress& progress = {});

}  // namespace tt::studies
