// Wall time for the timings that reports and progress lines give.
#pragma once

#include <chrono>

namespace tt::core {

/// Seconds of wall time (steady clock) since `start`.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace tt::core
