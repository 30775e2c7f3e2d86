// export's report at the edge (docs/cnc-export.md): per format a folder (sinumerik/, twincat/,
// heidenhain/, linuxcnc/) with the controller's files (io/cnc_out.hpp), and export.json /
// export.md with what each law leaves of the model [um].
#pragma once

#include <filesystem>
#include <vector>

#include "io/cnc_model_in.hpp"
#include "studies/cnc_export.hpp"

namespace tt::io {

/// What the report came from.
struct ExportSource {
  std::filesystem::path model;                     /// the fit.json
  const CncModelFile* file = nullptr;              /// read from it
  std::vector<std::filesystem::path> state_files;  /// --states, in order
  const StateSamples* samples = nullptr;           /// read from them
  int table_points = 51, grid = 1001;
};

/// Writes the report's files into `dir` (a folder the caller publishes).
void write_export(const std::filesystem::path& dir, const studies::CncExportReport& report,
                  const ExportSource& source);

}  // namespace tt::io
