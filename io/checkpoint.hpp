// Checkpoints of the thermal time loop, so that a long run killed overnight resumes where it was.
// One binary file beside the output directory (DIR.checkpoint), replaced atomically at each save:
//   "TTCKPT01", key (case hash, mesh hash, #nodes, #tets, order), state, FNV-1a of all before it.
// Native byte order: a checkpoint is for the machine that wrote it.
#pragma once

#include <cstdint>
#include <filesystem>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/thermal.hpp"

namespace tt::io {

/// What a checkpoint must match to be resumed: the resolved case and the mesh it was meshed to.
struct CheckpointKey {
  std::uint64_t case_hash = 0;  /// FNV-1a of the resolved case TOML without its source line
  std::uint64_t mesh_hash = 0;  /// FNV-1a of the node coordinates and the connectivity
  std::int64_t nodes = 0, tets = 0;
  std::int32_t order = 0;
  bool operator==(const CheckpointKey&) const = default;
};

CheckpointKey checkpoint_key(const core::CaseSpec& spec, const mesh::TetMesh& mesh);

/// DIR.checkpoint for the output directory DIR.
std::filesystem::path checkpoint_path(const std::filesystem::path& out_dir);

/// Throws IoError, before a run starts, when `file` could not be saved: it is not a regular file,
/// it is read-only (no write permission bit set, or not writable by this user), or a file cannot
/// be created beside it. The message says how to proceed.
void require_writable_checkpoint(const std::filesystem::path& file);

/// Writes via a temporary name and a rename: a kill leaves the previous checkpoint or this one;
/// a failure (IoError) leaves the previous checkpoint and no temporary file.
void write_checkpoint(const std::filesystem::path& file, const CheckpointKey& key,
                      const solvers::ThermalCheckpoint& state);

/// Throws IoError when the file cannot be read, DataError when it is truncated, corrupted or was
/// written for another case or mesh (the message says which).
solvers::ThermalCheckpoint read_checkpoint(const std::filesystem::path& file,
                                           const CheckpointKey& key);

}  // namespace tt::io
