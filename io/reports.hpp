// JSON reports of the mesher and the solvers.
#pragma once

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/mesher.hpp"

namespace tt::io {

/// mesh_report.json: nodes, tets, order, min_dihedral_deg, bodies{name: {volume_m3,
/// exact_volume_m3}}, points [{id, position, node, distance_m}], groups {name: area_m2}.
nlohmann::json mesh_report_json(const mesh::TetMesh& mesh, const mesh::MeshReport& report);

/// `value * scale` as a JSON number, or null when it is NaN or infinite, so that a file stays
/// valid JSON that says "not defined".
inline nlohmann::json finite_or_null(double value, double scale = 1.0) {
  return std::isfinite(value) ? nlohmann::json(value * scale) : nlohmann::json(nullptr);
}

/// A vector's values in a std::vector, as a JSON array takes them.
inline std::vector<double> as_vector(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

/// Writes a JSON value (pretty, via a temporary file and a rename).
void write_json(const std::filesystem::path& path, const nlohmann::json& value);

}  // namespace tt::io
