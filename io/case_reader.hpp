// Case files in, typed specs out: the only code that sees a case's TOML parse tree.
// Format by example: cases/sb1.toml. Lengths are in [geometry] length_unit ("m" or "mm"); every
// other quantity carries its unit in its key (density_kg_m3, step_s, h_W_m2K, ...).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/case_spec.hpp"

namespace tt::io {

/// The validated case in SI units with every default filled in. Files named by the case
/// (surface meshes, a duty-cycle CSV) are resolved against the case file's folder.
/// Throws core::IoError when the file cannot be read, and core::CaseError for anything wrong in
/// it, as "file:line: key.path = value: what was expected; hint".
core::CaseSpec read_case(const std::filesystem::path& file);

/// The case file and every file it names (surface meshes, a duty-cycle CSV): the inputs an
/// output folder must stay apart from.
std::vector<std::filesystem::path> case_input_files(const core::CaseSpec& spec);

/// `spec` with its duty cycle from a CSV "time_s,speed_rpm" (as duty_cycle.csv reads it) and its
/// end at `end_s` (default: the case's). Throws core::IoError when the file cannot be read and
/// core::CaseError, naming the file and line, for anything wrong in it, when its last row does
/// not start before the end, or when the run would exceed the step limits.
core::CaseSpec with_duty_cycle_csv(const core::CaseSpec& spec, const std::filesystem::path& file,
                                   std::optional<double> end_s);

/// read_case on text already in memory; `file` names it in messages and anchors relative paths.
core::CaseSpec case_from_toml(std::string_view text, const std::filesystem::path& file);

/// The resolved case as TOML: SI (length_unit = "m"), every default explicit, the duty cycle as
/// segments, surface files as absolute paths, doubles written to round-trip exactly.
/// read_case of this text gives back a spec equal to `spec` (except `source`).
std::string resolved_case_toml(const core::CaseSpec& spec);

}  // namespace tt::io
