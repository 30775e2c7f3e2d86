// The figures reported for a residual: RMS, largest magnitude and mean magnitude.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace tt::core {

/// In the residual's unit; all zero when no sample is finite.
struct ErrorFigures {
  double rms = 0, max_abs = 0, mae = 0;
};

/// The figures over the finite samples of `residual` (a missing reading is NaN and is skipped).
inline ErrorFigures error_figures(const Eigen::Ref<const Eigen::VectorXd>& residual) {
  double sum_sq = 0, sum_abs = 0, largest = 0, n = 0;
  for (const double e : residual) {
    if (!std::isfinite(e)) continue;
    sum_sq += e * e;
    sum_abs += std::abs(e);
    largest = std::max(largest, std::abs(e));
    n += 1;
  }
  if (n == 0) return {};
  return {std::sqrt(sum_sq / n), largest, sum_abs / n};
}

}  // namespace tt::core
