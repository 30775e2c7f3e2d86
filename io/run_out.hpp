// `thermotwin run`'s files from its report: mesh.vtu, boundary.vtp, points.vtp,
// mesh_report.json, case.resolved.toml, temperatures.csv, candidates.csv and
// candidate_temperatures.csv (surface candidates), thermal_error.csv, axis_polynomial.csv,
// fields.pvd and its steps, summary.json (docs/schemas/run_summary.schema.json) and the figures.
#pragma once

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "studies/virtual_run.hpp"

namespace tt::io {

/// Which thermal model ran, for summary.json's "model": the full model, or a reduced one of
/// `order` states read from `rom` (built from the case `built_from`).
struct RunModel {
  bool reduced = false;
  long order = 0;
  std::filesystem::path rom;
  std::string built_from;
};

/// The mesh files and the resolved case (`mesh` writes these alone).
void write_mesh_files(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                      const std::filesystem::path& dir);

/// --dump: #nodes, #times, temperatures [K], then #dofs, #times, displacements [m] when there
/// are any, as native int64 and doubles: results compared bit for bit by the reliability tests.
void write_dump(const solvers::VirtualRun& run, const std::filesystem::path& path);

/// Every file of a run into `dir` (an OutputDir's staging folder). `mesh_s`: the meshing time;
/// `started`: when the command started (summary.json's timings.total_s).
void write_run(const std::filesystem::path& dir, const mesh::TetMesh& mesh,
               const core::CaseSpec& spec, const studies::VirtualRunReport& report,
               const RunModel& model, double mesh_s, std::chrono::steady_clock::time_point started);

}  // namespace tt::io
