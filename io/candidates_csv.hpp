// candidates.csv: where a run's candidate sensors are, one per line, in the order of the
// temperature columns of candidate_temperatures.csv:
//   id,node,x_m,y_m,z_m
//   v1234,1234,0.16,0.0825,0.3125
// id is a named point's id or "v<node>" for a surface vertex; node indexes mesh.vtu's points.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace tt::io {

/// Run-directory files of the surface candidates (written by `run` when candidates = "surface").
inline constexpr const char* kCandidatesCsv = "candidates.csv";
inline constexpr const char* kCandidateTemperaturesCsv = "candidate_temperatures.csv";

struct CandidateTable {
  std::vector<std::string> ids;
  std::vector<int> nodes;      /// #candidates mesh node
  Eigen::MatrixX3d positions;  /// #candidates x 3 [m]
};

/// Written atomically; positions round-trip exactly. Throws DataError for sizes that disagree
/// or an id a CSV cell cannot hold (empty, comma, quote, line break).
void write_candidates_csv(const std::filesystem::path& path, const CandidateTable& table);

/// Throws IoError when the file cannot be read and DataError naming file and line for a
/// malformed one (wrong header, cell count, number, negative node, repeated id).
CandidateTable read_candidates_csv(const std::filesystem::path& path);

}  // namespace tt::io
