// calibrate --case: its report (studies/calibrate_with_model.hpp) as calibration.json
// (docs/schemas/calibration.schema.json, its head shared with the data-driven mode), report.md,
// augmented_case.toml (the first test run's inputs) and augmented/<run>.toml per test run,
// sensor_corrections.json, residuals.csv and the figures residual_before_after.png and effect.png.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "studies/calibrate_with_model.hpp"

namespace tt::io {

/// calibration.json's account of the choice: effects, runners_up, ambiguous, refit_rejected,
/// pairs, claimed_by and decision {rule, null_score, training_residual_whitened_ss,
/// noise_sigma_per_channel}.
nlohmann::json selection_json(const calibration::CalibrationResult& result);

/// Writes the report's files into `dir` (a folder the caller publishes).
void write_model_calibration(const std::filesystem::path& dir,
                             const studies::ModelCalibrationReport& report);

}  // namespace tt::io
