// A channel's error on held-out test data before and after a calibration: what both calibrate
// modes report per channel (calibration.json's before/after channels).
#pragma once

#include <string>

#include "core/error_figures.hpp"

namespace tt::studies {

/// Whether the test RMS after is above the one before, beyond rounding (a relative 1e-12): one
/// rule for calibration.json's `worse_than_before` and for the reports.
inline bool worse_after_than_before(const core::ErrorFigures& before,
                                    const core::ErrorFigures& after) {
  return after.rms > before.rms * (1 + 1e-12);
}

/// One channel's test residual, measured - model, before and after, in its unit ([K] for a
/// temperature, [m] for a displacement).
struct ChannelTestFigures {
  std::string id;
  bool temperature = false;
  core::ErrorFigures before, after;
  bool worse_after_than_before() const { return studies::worse_after_than_before(before, after); }
};

}  // namespace tt::studies
