// The part of calibration.json both calibrate modes write alike (docs/schemas/
// calibration.schema.json: format, mode, the runs, the test figures before and after, per channel,
// and the channels that got worse); io/calibration_model_out (--case) and io/calibration_data_out
// (without) add their own parts.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "studies/test_figures.hpp"

namespace tt::io {

/// The test data's figures of one calibrate run.
struct CalibrationHead {
  std::string mode;  /// "model (--case)" or "data-driven (no --case)"
  std::vector<std::string> training_runs, test_runs;
  /// RMS over the temperature channels [K]; unset when no model predicts temperatures
  std::optional<double> temperature_rms_K_before, temperature_rms_K_after;
  /// why there is no temperature figure (written beside the null), when there is none
  std::string temperature_note;
  /// RMS over the displacement channels [um]
  double displacement_rms_um_before = 0, displacement_rms_um_after = 0;
  std::vector<studies::ChannelTestFigures> channels;
};

/// {format, mode, training_runs, test_runs, before, after, after_worse_than_before_on_test}: the
/// channels' figures suffixed _K (temperature) or _um (displacement), after's with
/// worse_than_before.
nlohmann::json calibration_head_json(const CalibrationHead& head);

}  // namespace tt::io
