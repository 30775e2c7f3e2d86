// The `thermotwin probes --in RAW.csv --out DIR` command as one function, and the virtual raw
// file that lets it run on a simulated spindle. The CLI only parses flags and calls these.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "probes/alignment.hpp"
#include "probes/drift.hpp"
#include "probes/raw_csv.hpp"
#include "probes/virtual_signal.hpp"

namespace tt::probes {

struct ProbeOptions {
  /// Speed, sample rate and D when the raw file's header does not give them (must agree if both)
  RawCsvConstants constants;
  AlignmentOptions alignment;
  /// True drift in drift-CSV form (time_s,x1_um,y1_um,x2_um,y2_um[,z_um], one row per reading),
  /// e.g. from write_virtual_raw_csv; when given, every method is scored against it.
  std::optional<std::filesystem::path> truth_csv;
};

struct MethodSummary {
  AlignmentMethod method = AlignmentMethod::information_distance;
  std::string file;  ///< name inside the output directory
  /// Largest |drift − info-distance drift| over readings and directions [m]
  double max_difference_from_info_m = 0.0;
  std::optional<DriftError> error_vs_truth;
};

struct ProbeRunSummary {
  std::size_t readings = 0;
  bool has_axial = false;
  AlignmentPlan plan;
  /// Smallest (runner-up − best) / runner-up of the information distance over readings 2..N;
  /// near 0 means some reading had two equally good angles.
  double min_relative_margin = 1.0;
  std::vector<MethodSummary> methods;  ///< info, xcorr, noalign, revmean
};

/// Reads `in`, recovers drift and tilt with the information-distance alignment and, for
/// comparison, with cross-correlation, without alignment and with revolution means, and writes
/// into the existing folder `dir`: drift.csv (the method's result), drift_xcorr.csv,
/// drift_noalign.csv, drift_revmean.csv, alignment.csv and summary.json, nothing before the input
/// is read whole. Publishing `dir` all or nothing is the caller's (the CLI's io::OutputDir).
/// Throws DataError (file:line: column ...) or IoError.
ProbeRunSummary run_probes_command(const std::filesystem::path& in,
                                   const std::filesystem::path& dir, const ProbeOptions& options);

/// Simulates readings of `history` (virtual_record), writes them as a raw CSV to `raw_csv`
/// (atomically) and, if `truth_csv` is given, the true drift relative to the first reading
/// in drift-CSV form. Returns the record and the true start angles.
VirtualRecord write_virtual_raw_csv(
    const std::filesystem::path& raw_csv, const VirtualProbeSetup& setup,
    const DriftHistory& history,
    const std::optional<std::filesystem::path>& truth_csv = std::nullopt);

}  // namespace tt::probes
