// A reduced-order model on disk (`thermotwin reduce CASE --out DIR`), documented in
// docs/reduced-order.md:
//   reduced_model.json  what it is: format, order, inputs, outputs, the case it was built from and
//                       its hashes, how the basis was built, the validation against the full model;
//   reduced_model.bin   the numbers: "TTROM001", then named matrices (name, rows, cols, doubles
//                       column-major), FNV-1a of all before it; native byte order.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/twin.hpp"

namespace tt::io {

/// What a reduced model must match to be used for a case: the machine it models (geometry,
/// materials, films, sources and their places; not the duty cycle, feed program, sinks, initial
/// temperature, time step or outputs, which are its inputs) and the mesh it was built on.
struct ReducedModelKey {
  std::uint64_t model_hash = 0;  /// FNV-1a of the resolved case with its inputs normalised
  std::uint64_t mesh_hash = 0;   /// FNV-1a of the node coordinates and the connectivity
  std::int64_t nodes = 0;
  bool operator==(const ReducedModelKey&) const = default;
};

ReducedModelKey reduced_model_key(const core::CaseSpec& spec, const mesh::TetMesh& mesh);

struct ReducedModelFile {
  solvers::Twin twin;  /// the reduced model and the case's outputs on it
  ReducedModelKey key;
  std::string case_name;
  std::string case_file;
  nlohmann::json info;  /// everything else for the user: build, validation
};

/// Writes both files into `dir` (an OutputDir's staging folder).
void write_reduced_model(const std::filesystem::path& dir, const ReducedModelFile& file);

/// Reads a reduced model. Throws IoError when a file cannot be read, DataError when it is not one,
/// is corrupted or inconsistent (the message names the file and says to rebuild it).
ReducedModelFile read_reduced_model(const std::filesystem::path& dir);

/// Throws DataError naming both when `file` was built for another machine or mesh than `key`.
void check_reduced_model_fits(const ReducedModelFile& file, const ReducedModelKey& key,
                              const std::filesystem::path& dir);

}  // namespace tt::io
