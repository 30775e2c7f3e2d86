// calibrate without --case: its report as calibration.json (docs/schemas/calibration.schema.json,
// shared with the --case mode), report.md, and per channel residual_<channel>.csv and .png.
#pragma once

#include <filesystem>

#include "io/measured_segments.hpp"
#include "studies/calibrate_from_data.hpp"

namespace tt::io {

/// Writes the report's files into `dir` (a folder the caller publishes); `runs` says where each
/// run's rows went.
void write_data_calibration(const std::filesystem::path& dir,
                            const studies::DataCalibrationReport& report, const SplitRuns& runs);

}  // namespace tt::io
