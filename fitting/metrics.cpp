#include "fitting/metrics.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "core/errors.hpp"

namespace tt::fitting {

double residual_std(const Eigen::VectorXd& residual) {
  const Eigen::Index n = residual.size();
  if (n < 2)
    throw core::DataError("residual standard deviation of " + std::to_string(n) +
                          " readings; formula 5 needs N >= 2");
  return std::sqrt(residual.squaredNorm() / static_cast<double>(n - 1));
}

Accuracy accuracy(const std::vector<double>& s) {
  if (s.empty()) throw core::DataError("accuracy over 0 groups; expected at least one S_i");
  Accuracy result;
  result.s = s;
  double sum = 0.0;
  for (double v : s) sum += v;
  const double k = static_cast<double>(s.size());
  result.sm = sum / k;
  if (s.size() < 2) {
    result.s_sigma = std::numeric_limits<double>::quiet_NaN();
  } else {
    double squares = 0.0;
    for (double v : s) squares += (v - result.sm) * (v - result.sm);
    result.s_sigma = std::sqrt(squares / (k - 1.0));
  }
  return result;
}

double mean_square(const Accuracy& a) {
  if (a.s.empty()) throw core::DataError("mean square over 0 groups; expected at least one S_i");
  double sum = 0.0;
  for (double v : a.s) sum += v * v;
  return sum / static_cast<double>(a.s.size());
}

}  // namespace tt::fitting
