// The model a CNC export approximates (fitting::CncModel), read from the fit.json that
// `thermotwin fit` writes: the TCP targets dx, dy and dz (the position-independent drift) and, for
// a case with a feed axis, the axis points' models and the axis polynomial they give (the
// polynomial `fit` reports, solvers::axis_polynomial of their coefficients).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fitting/cnc_export.hpp"

namespace tt::io {

struct CncModelFile {
  fitting::CncModel model;
  /// TCP targets that are not a direction (e.g. tilts, dx_z1): no controller axis takes them
  std::vector<std::string> ignored_targets;
  /// names of the models read: the TCP targets, then "<point>_<direction>" of the axis points
  std::vector<std::string> targets;
};

/// From a parsed fit.json; `origin` names the file in messages. Throws DataError naming the file
/// and key for a missing or malformed key (e.g. an axis section written before fit.json kept the
/// axis models' coefficients), a model that is not linear in its regressors, or a file with
/// neither a TCP direction target nor an axis.
CncModelFile cnc_model(const nlohmann::json& fit, const std::string& origin);

/// cnc_model of the file at `path` (IoError when it cannot be read, DataError when not JSON).
CncModelFile read_cnc_model(const std::filesystem::path& path);

}  // namespace tt::io
