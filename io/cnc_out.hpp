// The controllers' own files for the compensation laws of fitting/cnc_export.hpp
// (docs/cnc-export.md): SINUMERIK 840D sl setting data written by a synchronized action, a TwinCAT
// PLC's table-based position compensation, a Heidenhain TNC PLC's thermal-expansion offset with its
// tables in the compensation-value-table layout, and a LinuxCNC HAL file driving external offsets.
// Lengths are written in mm, the controllers' unit; the basis functions in their own units (K,
// rpm).
#pragma once

#include <string>
#include <vector>

#include "core/enum_names.hpp"
#include "fitting/cnc_export.hpp"

namespace tt::io {

/// The four controllers.
enum class CncFormat { sinumerik, twincat, heidenhain, linuxcnc };

/// The formats' names on the command line and in export.json.
inline constexpr std::array<core::Named<CncFormat>, 4> kCncFormatNames{{
    {CncFormat::sinumerik, "sinumerik"},
    {CncFormat::twincat, "twincat"},
    {CncFormat::heidenhain, "heidenhain"},
    {CncFormat::linuxcnc, "linuxcnc"},
}};
static_assert(core::one_to_one(kCncFormatNames));

/// The format's name in kCncFormatNames.
std::string format_name(CncFormat format);

/// The format named `name`; DataError listing the four otherwise.
CncFormat format_of(const std::string& name);

/// How each controller's law is built from the model (one place: the files and the error figures
/// use the same law).
/// sinumerik: fitting::line_law; twincat: table_law at `table_points`, no rounding (LREAL);
/// heidenhain: table_law at `table_points`, rounded to 0.1 µm (PLC module 9231's unit);
/// linuxcnc: polynomial_law, truncated to the eoffset count (kLinuxcncScaleMm).
fitting::ControllerLaw controller_law(CncFormat format, const fitting::CncModel& model,
                                      int table_points);

/// axis.L.eoffset-scale written by the HAL file [mm per count].
inline constexpr double kLinuxcncScaleMm = 1e-5;

/// One file to write: a name inside the output folder and its text.
struct CncFile {
  std::string name, text;
};

/// The controller's files for `law` (made by controller_law for `format`). `source` names the
/// fit.json in the files' headers.
std::vector<CncFile> cnc_files(CncFormat format, const fitting::CncModel& model,
                               const fitting::ControllerLaw& law, const std::string& source);

}  // namespace tt::io
