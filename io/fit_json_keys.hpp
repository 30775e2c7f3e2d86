// A JSON file read, and keys of a fit.json read with messages that name the file, the target and
// the key path, e.g. "fit.json: target 'dz': chosen.coefficients.terms[0].um_per_K = "x":
// expected a finite number".
// Shared by the readers of fit.json (io/fit_model_in.cpp, io/cnc_model_in.cpp) and of
// sigma_calibration.json (io/sigma_calibration_io.cpp).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.hpp"

namespace tt::io::fit_keys {

using nlohmann::json;

/// Where a key sits, for messages: "fit.json: target 'dz': chosen.coefficients.kind", or
/// "fit.json: axis.positions_m" for a key outside any target (target empty).
struct Place {
  std::string origin, target;
  /// what a missing key suggests
  std::string hint = "give a fit.json written by `thermotwin fit` or `thermotwin fit --data`";
  std::string at(const std::string& key) const {
    return origin + ": " + (target.empty() ? "" : "target '" + target + "': ") + key;
  }
};

/// The parsed JSON file at `path`: IoError naming it and `expected` ("a fit.json file") when it
/// cannot be read, DataError when it is not JSON.
inline json read_json(const std::filesystem::path& path, const std::string& expected) {
  std::ifstream in(path);
  if (!in || std::filesystem::is_directory(path))
    throw core::IoError(path.string() + ": cannot read (expected " + expected + ")");
  std::stringstream text;
  text << in.rdbuf();
  try {
    return json::parse(text.str());
  } catch (const json::parse_error& e) {
    throw core::DataError(path.string() + ": not JSON: " + e.what());
  }
}

inline const json& member(const json& j, const std::string& key, const Place& p,
                          const std::string& path) {
  if (!j.is_object() || !j.contains(key))
    throw core::DataError(p.at(path + key) + " is missing; hint: " + p.hint);
  return j.at(key);
}

inline double number_at(const json& j, const std::string& key, const Place& p,
                        const std::string& path) {
  const json& v = member(j, key, p, path);
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    throw core::DataError(p.at(path + key) + " = " + v.dump() + ": expected a finite number");
  return v.get<double>();
}

inline std::vector<std::string> names_at(const json& j, const std::string& key, const Place& p,
                                         const std::string& path) {
  const json& v = member(j, key, p, path);
  std::vector<std::string> names;
  if (v.is_array())
    for (const json& n : v)
      if (n.is_string()) names.push_back(n.get<std::string>());
  if (!v.is_array() || names.size() != v.size())
    throw core::DataError(p.at(path + key) + " = " + v.dump() + ": expected a list of names");
  return names;
}

inline Eigen::VectorXd vector_at(const json& j, const std::string& key, const Place& p,
                                 const std::string& path, double factor = 1.0) {
  const json& v = member(j, key, p, path);
  if (!v.is_array())
    throw core::DataError(p.at(path + key) + " = " + v.dump() + ": expected a list of numbers");
  Eigen::VectorXd out(static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_number() || !std::isfinite(v[i].get<double>()))
      throw core::DataError(p.at(path + key) + "[" + std::to_string(i) + "] = " + v[i].dump() +
                            ": expected a finite number");
    out(static_cast<Eigen::Index>(i)) = v[i].get<double>() * factor;
  }
  return out;
}

}  // namespace tt::io::fit_keys
