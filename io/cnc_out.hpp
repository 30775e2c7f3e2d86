// The controllers' own files for the compensation laws of fitting/cnc_export.hpp
// (docs/cnc-export.md): SINUMERIK 840D sl setting data written by a synchronized action, a TwinCAT
// PLC's table-based position compensation, a Heidenhain TNC PLC's thermal-expansion offset with its
// tables in the compensation-value-table layout, and a LinuxCNC HAL file driving external offsets.
// Lengths are written in mm, the controllers' unit; the basis functions in their own units (K,
// rpm).
#pragma once

#include <string>
#include <vector>

#include "fitting/cnc_export.hpp"

namespace tt::io {

/// The format's name in fitting::kCncFormatNames.
std::string format_name(fitting::CncFormat format);

/// The format named `name`; DataError listing the four otherwise.
fitting::CncFormat format_of(const std::string& name);

/// One file to write: a name inside the output folder and its text.
struct CncFile {
  std::string name, text;
};

/// The controller's files for `law` (made by fitting::controller_law for `format`). `source` names
/// the fit.json in the files' headers.
std::vector<CncFile> cnc_files(fitting::CncFormat format, const fitting::CncModel& model,
                               const fitting::ControllerLaw& law, const std::string& source);

}  // namespace tt::io
