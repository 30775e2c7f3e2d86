// A result that overflowed (NaN, ±inf) is an error, never a number written to a file: each
// stage checks what it returns with require_finite, and its message says what went non-finite
// and where it came from.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <sstream>
#include <string>

#include "core/errors.hpp"

namespace tt::core {

/// Throws SolverError "<what> is not finite (<value> at row r, column c): <origin>" when `values`
/// holds a NaN or an infinity.
inline void require_finite(const Eigen::Ref<const Eigen::MatrixXd>& values, const std::string& what,
                           const std::string& origin) {
  if (values.allFinite()) return;
  for (Eigen::Index c = 0; c < values.cols(); ++c)
    for (Eigen::Index r = 0; r < values.rows(); ++r)
      if (!std::isfinite(values(r, c))) {
        std::ostringstream o;
        o << what << " is not finite (" << values(r, c) << " at row " << r << ", column " << c
          << "): " << origin << "; nothing is written";
        throw SolverError(o.str());
      }
}

/// The same for one number.
inline void require_finite(double value, const std::string& what, const std::string& origin) {
  require_finite(Eigen::Matrix<double, 1, 1>::Constant(value), what, origin);
}

}  // namespace tt::core
