// VTK XML output of the mesh, its boundary, its named points and the field history, for ParaView.
// Every file is binary, appended and zlib-compressed, and is written to a temporary name and
// renamed, so a failed run never leaves a truncated file that looks whole. VTK stays inside
// vtk_out.cpp: this header exposes no VTK type.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "mesh/tet_mesh.hpp"

namespace tt::io {

/// The volume mesh as a .vtu: VTK_TETRA (order 1) or VTK_QUADRATIC_TETRA (order 2) cells over all
/// nodes; cell data `region` (int); field data `region_names` (string per region id).
void write_mesh_vtu(const mesh::TetMesh& mesh, const std::filesystem::path& path);

/// All faces of mesh.faces as a .vtp of triangles. Polydata cannot hold quadratic triangles, so an
/// order-2 face is written as its corner triangle. Points are the face corners only; point data
/// `node` (int) maps each back to TetMesh::nodes. Cell data: `group_id` (int, -1 for none),
/// `group_name` (string, empty for none), `interface` (int, 1 when the face separates two tets),
/// `region` (int, region of face_tet). Field data `group_names` (string per group id).
void write_boundary_vtp(const mesh::TetMesh& mesh, const std::filesystem::path& path);

/// The named points as a .vtp of vertices at NamedNode::position, with point data `id` (string),
/// `index` (int, position in mesh.points) and `node` (int, the mesh node or -1).
void write_points_vtp(const mesh::TetMesh& mesh, const std::filesystem::path& path);

/// One named array of a time step. The name carries the unit (`temperature_degC`,
/// `displacement_m`, `von_mises_Pa`).
struct NamedField {
  std::string name;
  int components = 1;      /// values per entity: 1 for a scalar, 3 for a vector
  Eigen::VectorXd values;  /// #entities * components, entity-major (x0 y0 z0 x1 y1 z1 ...)
};

/// A cloud of labelled points (e.g. candidate sensors) with per-point fields, for ParaView:
/// point data `id` (string) and every field (#points * components values each).
void write_point_cloud_vtp(const std::filesystem::path& path, const std::vector<std::string>& ids,
                           const Eigen::MatrixX3d& positions,
                           const std::vector<NamedField>& fields);

/// One written step of a series.
struct SeriesStep {
  double time_s = 0.0;
  std::filesystem::path file;  /// the .vtu, in the series directory
};

/// Writes a field history as one .vtu per output time plus the `STEM.pvd` collection that
/// ParaView opens as a time series. The mesh topology is built once and shared by every step.
///
/// Point fields have #nodes entities; on an order-2 mesh a point field may also have
/// corner_count entities (a field of the linear thermal solution), whose mid-edge values are
/// then the mean of the two corners of their edge. Cell fields have #tets entities. Every step
/// also carries the cell data `region`.
class FieldSeriesWriter {
 public:
  /// Creates `dir` when missing. Step files are `dir/STEM_0000.vtu`, `dir/STEM_0001.vtu`, ...
  FieldSeriesWriter(const mesh::TetMesh& mesh, std::filesystem::path dir,
                    std::string stem = "fields");
  ~FieldSeriesWriter();
  FieldSeriesWriter(const FieldSeriesWriter&) = delete;
  FieldSeriesWriter& operator=(const FieldSeriesWriter&) = delete;

  /// Writes the step at `time_s` (strictly after the previous step) and returns its path.
  std::filesystem::path add_step(double time_s, const std::vector<NamedField>& point_fields,
                                 const std::vector<NamedField>& cell_fields = {});

  /// Writes `dir/STEM.pvd` listing every step written so far and returns its path. May be called
  /// again after further steps; each call replaces the index.
  std::filesystem::path finish();

  const std::vector<SeriesStep>& steps() const { return steps_; }

 private:
  struct Geometry;  // the shared VTK grid, hidden from includers
  std::unique_ptr<Geometry> geometry_;
  std::filesystem::path dir_;
  std::string stem_;
  std::vector<SeriesStep> steps_;
};

/// The text of a ParaView .pvd collection listing `steps` (file names relative to the .pvd).
std::string pvd_collection(const std::vector<SeriesStep>& steps);

}  // namespace tt::io
