// Adapter to TetGen: typed PLC and options in, linear tets out; TetGen's int exceptions become
// MeshError with what was asked.
#pragma once

#include "mesh/plc.hpp"

namespace tt::mesh::tetgen {

/// Tetrahedralises `plc` with quality bounds and per-region volume bounds. Throws MeshError.
LinearTets tetrahedralize(const Plc& plc, const TetgenOptions& options);

}  // namespace tt::mesh::tetgen
