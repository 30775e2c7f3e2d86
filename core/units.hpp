// Unit conversions used at the edges (case files, data files, reports): inside, temperatures are
// in K; degC exists only where a file or a report says so in its key or column name.
#pragma once

namespace tt::core {

/// T [K] = T [degC] + kCelsiusOffset.
inline constexpr double kCelsiusOffset = 273.15;

/// Lengths at the edges: x [mm] = x [m] * kMillimetresPerMetre, x [um] = x [m] *
/// kMicrometresPerMetre; x [m] = x [um] * kMetresPerMicrometre (the factor, not the division, so
/// that a value read is the value the file gives times 1e-6).
inline constexpr double kMillimetresPerMetre = 1e3;
inline constexpr double kMicrometresPerMetre = 1e6;
inline constexpr double kMetresPerMicrometre = 1e-6;

}  // namespace tt::core
