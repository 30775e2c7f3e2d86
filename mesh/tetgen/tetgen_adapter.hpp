// Adapter to TetGen: typed PLC and options in, linear tets out. TetGen runs in a forked child
// process, so its failures (an int code, or a crash) become MeshError with what was asked and
// what TetGen printed, and never take the caller down.
#pragma once

#include "mesh/plc.hpp"

namespace tt::mesh::tetgen {

/// Tetrahedralises `plc` with quality bounds and per-region volume bounds. Throws MeshError.
/// Forks once per call and waits for that child, so a caller that reaps every child
/// (waitpid(-1, ...)) on another thread may take its status away.
LinearTets tetrahedralize(const Plc& plc, const TetgenOptions& options);

}  // namespace tt::mesh::tetgen
