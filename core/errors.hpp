// Typed errors of thermotwin. The library throws these and never prints, exits or aborts;
// drivers catch `tt::core::Error`, print what(), and return non-zero.
#pragma once

#include <stdexcept>
#include <string>

namespace tt::core {

/// Base of every project error. The message names what failed, the value received, the value
/// expected and a hint, e.g. `materials.cast_iron.conductivity_W_mK = -45: must be > 0`.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A case file (TOML) that is malformed, incomplete or inconsistent.
class CaseError : public Error {
 public:
  using Error::Error;
};
/// Geometry that cannot be built: overlapping bodies, open surfaces, points outside the parts.
class GeometryError : public Error {
 public:
  using Error::Error;
};
/// The mesher failed or produced something unusable.
class MeshError : public Error {
 public:
  using Error::Error;
};
/// A linear solver or time integrator failed (singular matrix, no constraint on rigid motion).
class SolverError : public Error {
 public:
  using Error::Error;
};
/// Measured data or candidate histories that are malformed.
class DataError : public Error {
 public:
  using Error::Error;
};
/// A file could not be read or written.
class IoError : public Error {
 public:
  using Error::Error;
};

/// "file:line: message" when a line is known, "file: message" otherwise.
std::string located(const std::string& file, int line, const std::string& message);

}  // namespace tt::core
