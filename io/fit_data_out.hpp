// fit --data's report at the edge: fit.json (docs/schemas/fit.schema.json), summary.md,
// compensation.csv (the chosen models on the test segments), window_<channel>.csv and .png (a
// window inside a run) and network_<channel>.pt (with the network).
#pragma once

#include <filesystem>
#include <string>

#include "io/fit_data_in.hpp"
#include "studies/fit_from_data.hpp"

namespace tt::io {

/// A line of progress: the blocks (before any channel), else the last channel's choice and test
/// RMS [um].
std::string data_fit_progress(const studies::DataFitReport& report);

/// Writes the report's files into `dir` (a folder the caller publishes); `runs` says which runs
/// and which window they came from.
void write_data_fit(const std::filesystem::path& dir, const studies::DataFitReport& report,
                    const DataFitRuns& runs);

}  // namespace tt::io
