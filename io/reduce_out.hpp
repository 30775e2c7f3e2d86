// reduce's report at the edge: reduced_model.json / .bin (io/reduced_model_io.hpp) with the
// validation and the timings in its record, and validation.csv (docs/reduced-order.md).
#pragma once

#include <filesystem>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "studies/reduce_case.hpp"

namespace tt::io {

/// Writes the report's files into `dir` (a folder the caller publishes). `case_file`: the case the
/// model was built from (recorded absolute); `total_s`: the command's wall time so far [s].
void write_reduce(const std::filesystem::path& dir, const studies::ReduceReport& report,
                  const core::CaseSpec& spec, const mesh::TetMesh& mesh,
                  const std::filesystem::path& case_file, double total_s);

}  // namespace tt::io
