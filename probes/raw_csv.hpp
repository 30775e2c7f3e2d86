// The probe files at the edge: raw readings in (µm, see docs/probes.md "Raw CSV format"), drift
// series out. Units become SI on reading and leave SI on writing.
#pragma once

#include <filesystem>
#include <optional>

#include "probes/record.hpp"

namespace tt::probes {

/// Constants of a record given outside the file; a constant also present in the file's header
/// comment must agree with it (a silent override would hide a mistake).
struct RawCsvConstants {
  std::optional<double> speed_rpm;
  std::optional<double> sample_rate_hz;
  std::optional<double> probe_distance_mm;
};

/// Reads a raw CSV; throws DataError naming file, line and column for anything malformed,
/// including a reading shorter than one revolution, and IoError when it cannot be opened.
ProbeRecord read_raw_csv(const std::filesystem::path& file, const RawCsvConstants& given = {});

/// The raw CSV text of a record (header comment with the constants, column line, rows).
std::string raw_csv_text(const ProbeRecord& record);

/// A drift series as CSV: time_s,x1_um,y1_um,x2_um,y2_um,tilt_x_urad,tilt_y_urad[,z_um].
std::string drift_csv_text(const DriftSeries& series);

/// Reads a drift history: columns time_s,x1_um,y1_um,x2_um,y2_um required, z_um optional, others
/// (e.g. the tilt columns of a drift.csv) ignored, in any order. '#' lines are comments.
DriftHistory read_drift_history_csv(const std::filesystem::path& file);

/// Writes `text` to file.partial and renames it to `file`, so a failure never leaves a
/// truncated file that looks whole. Throws IoError.
void write_text_atomically(const std::filesystem::path& file, const std::string& text);

}  // namespace tt::probes
