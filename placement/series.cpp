#include "placement/series.hpp"

#include <string>

#include "core/errors.hpp"

namespace tt::placement {

namespace {

void require_increasing(const Eigen::VectorXd& times_s) {
  if (times_s.size() < 2)
    throw core::DataError("placement: " + std::to_string(times_s.size()) +
                          " time points: need at least 2 to resample");
  for (Eigen::Index i = 1; i < times_s.size(); ++i)
    if (!(times_s(i) > times_s(i - 1)))
      throw core::DataError("placement: times_s[" + std::to_string(i) +
                            "] = " + std::to_string(times_s(i)) + " s after " +
                            std::to_string(times_s(i - 1)) +
                            " s: times must be strictly increasing; hint: drop repeated outputs");
}

}  // namespace

Eigen::VectorXd sample_times(const Eigen::VectorXd& times_s, int samples) {
  require_increasing(times_s);
  if (samples < 2)
    throw core::DataError("placement.samples = " + std::to_string(samples) +
                          ": must be >= 2 (the patent uses 100)");
  const double t0 = times_s(0);
  const double span = times_s(times_s.size() - 1) - t0;
  Eigen::VectorXd t(samples);
  for (int k = 1; k <= samples; ++k) t(k - 1) = t0 + span * k / samples;
  t(samples - 1) = times_s(times_s.size() - 1);  // exact end despite rounding
  return t;
}

Eigen::MatrixXd resampled(const Eigen::VectorXd& times_s, const Eigen::MatrixXd& values,
                          const Eigen::VectorXd& new_times_s) {
  require_increasing(times_s);
  if (values.rows() != times_s.size())
    throw core::DataError("placement: histories have " + std::to_string(values.rows()) +
                          " rows for " + std::to_string(times_s.size()) +
                          " time points: expected one row per time point");
  const Eigen::Index n = times_s.size();
  Eigen::MatrixXd out(new_times_s.size(), values.cols());
  Eigen::Index seg = 0;  // times_s(seg) <= t <= times_s(seg + 1), the new times may be in any order
  for (Eigen::Index k = 0; k < new_times_s.size(); ++k) {
    const double t = new_times_s(k);
    if (t < times_s(0) || t > times_s(n - 1))
      throw core::DataError("placement: sample time " + std::to_string(t) + " s outside [" +
                            std::to_string(times_s(0)) + ", " + std::to_string(times_s(n - 1)) +
                            "] s: cannot extrapolate histories");
    if (t < times_s(seg)) seg = 0;
    while (seg + 2 < n && t > times_s(seg + 1)) ++seg;
    const double w = (t - times_s(seg)) / (times_s(seg + 1) - times_s(seg));
    out.row(k) = (1.0 - w) * values.row(seg) + w * values.row(seg + 1);
  }
  return out;
}

Eigen::MatrixXd unit_columns(const Eigen::MatrixXd& values) {
  Eigen::MatrixXd z = values.rowwise() - values.colwise().mean();
  for (Eigen::Index j = 0; j < z.cols(); ++j) {
    const double norm = z.col(j).norm();
    const double scale = values.col(j).cwiseAbs().maxCoeff();
    // Relative test: a history that varies by round-off only carries no information.
    if (norm <= 1e-12 * scale * std::sqrt(static_cast<double>(z.rows())) || norm == 0.0)
      z.col(j).setZero();
    else
      z.col(j) /= norm;
  }
  return z;
}

}  // namespace tt::placement
