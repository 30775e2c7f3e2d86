// Unit conversions used at the edges (case files, data files, reports): inside, temperatures are
// in K; degC exists only where a file or a report says so in its key or column name.
#pragma once

namespace tt::core {

/// T [K] = T [degC] + kCelsiusOffset.
inline constexpr double kCelsiusOffset = 273.15;

}  // namespace tt::core
