#include "io/vtk_out.hpp"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkCommand.h>
#include <vtkDoubleArray.h>
#include <vtkExecutive.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>
#include <sstream>
#include <system_error>
#include <utility>

#include "core/errors.hpp"
#include "io/atomic_dir.hpp"

namespace tt::io {

namespace fs = std::filesystem;

namespace {

/// Local corner pairs of the mid-edge nodes 4..9 of a VTK quadratic tetra.
constexpr std::array<std::pair<int, int>, 6> kTetEdges = {
    {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}}};

std::string str(long long value) {
  return std::to_string(value);
}

[[noreturn]] void fail_mesh(const std::string& what) {
  throw core::MeshError("cannot write mesh: " + what +
                        "; hint: the mesher must fill every per-tet and per-face array");
}

/// The order, the tets' node indices and regions.
void check_tets(const mesh::TetMesh& mesh) {
  if (mesh.order != 1 && mesh.order != 2) {
    fail_mesh("order = " + str(mesh.order) + ": expected 1 or 2");
  }
  const long long node_count = mesh.nodes.rows();
  const long long tet_count = mesh.tets.rows();
  if (tet_count > 0 && mesh.tets.cols() != mesh.nodes_per_tet()) {
    fail_mesh("tets have " + str(mesh.tets.cols()) + " columns: expected " +
              str(mesh.nodes_per_tet()) + " for order " + str(mesh.order));
  }
  if (static_cast<long long>(mesh.tet_region.size()) != tet_count) {
    fail_mesh("tet_region has " + str(mesh.tet_region.size()) + " entries: expected one per tet (" +
              str(tet_count) + ")");
  }
  for (long long t = 0; t < tet_count; ++t) {
    for (int k = 0; k < mesh.tets.cols(); ++k) {
      const int node = mesh.tets(t, k);
      if (node < 0 || node >= node_count) {
        fail_mesh("tet " + str(t) + " node " + str(k) + " = " + str(node) + ": expected 0.." +
                  str(node_count - 1));
      }
    }
    const int region = core::index_of(mesh.tet_region[t]);
    if (region < 0 ||
        (!mesh.region_names.empty() && region >= static_cast<int>(mesh.region_names.size()))) {
      fail_mesh("tet " + str(t) + " region = " + str(region) + ": expected 0.." +
                str(static_cast<long long>(mesh.region_names.size()) - 1));
    }
  }
}

/// The per-face arrays' sizes.
void check_face_arrays(const mesh::TetMesh& mesh) {
  const long long face_count = mesh.faces.rows();
  if (face_count > 0 && mesh.faces.cols() != mesh.nodes_per_face()) {
    fail_mesh("faces have " + str(mesh.faces.cols()) + " columns: expected " +
              str(mesh.nodes_per_face()) + " for order " + str(mesh.order));
  }
  const auto face_array_size = [&](const char* name, std::size_t size) {
    if (static_cast<long long>(size) != face_count) {
      fail_mesh(std::string(name) + " has " + str(size) + " entries: expected one per face (" +
                str(face_count) + ")");
    }
  };
  face_array_size("face_tet", mesh.face_tet.size());
  face_array_size("face_other_tet", mesh.face_other_tet.size());
  face_array_size("face_group", mesh.face_group.size());
}

/// Each face's nodes, tets and group.
void check_faces(const mesh::TetMesh& mesh) {
  check_face_arrays(mesh);
  const long long node_count = mesh.nodes.rows();
  const long long tet_count = mesh.tets.rows();
  for (long long f = 0; f < mesh.faces.rows(); ++f) {
    for (int k = 0; k < mesh.faces.cols(); ++k) {
      const int node = mesh.faces(f, k);
      if (node < 0 || node >= node_count) {
        fail_mesh("face " + str(f) + " node " + str(k) + " = " + str(node) + ": expected 0.." +
                  str(node_count - 1));
      }
    }
    if (mesh.face_tet[f] < 0 || mesh.face_tet[f] >= tet_count) {
      fail_mesh("face_tet[" + str(f) + "] = " + str(mesh.face_tet[f]) + ": expected 0.." +
                str(tet_count - 1));
    }
    if (mesh.face_other_tet[f] < -1 || mesh.face_other_tet[f] >= tet_count) {
      fail_mesh("face_other_tet[" + str(f) + "] = " + str(mesh.face_other_tet[f]) +
                ": expected -1.." + str(tet_count - 1));
    }
    const int group = core::index_of(mesh.face_group[f]);
    if (group < -1 || group >= static_cast<int>(mesh.group_names.size())) {
      fail_mesh("face_group[" + str(f) + "] = " + str(group) + ": expected -1.." +
                str(static_cast<long long>(mesh.group_names.size()) - 1));
    }
  }
}

/// Throws MeshError when the arrays of `mesh` disagree in size or index out of range; the writers
/// would otherwise read past an array or write a file ParaView rejects.
void check_mesh(const mesh::TetMesh& mesh) {
  check_tets(mesh);
  check_faces(mesh);
  const long long node_count = mesh.nodes.rows();
  for (std::size_t p = 0; p < mesh.points.size(); ++p) {
    const int node = mesh.points[p].node;
    if (node < -1 || node >= node_count) {
      fail_mesh("points[" + str(p) + "] (" + mesh.points[p].id + ") node = " + str(node) +
                ": expected -1.." + str(node_count - 1));
    }
  }
}

/// Collects the messages VTK raises on a writer, so they end up in the exception instead of on
/// stderr (VTK hands an error to an observer instead of its output window when one is attached).
class MessageCollector : public vtkCommand {
 public:
  static MessageCollector* New() { return new MessageCollector; }
  void Execute(vtkObject*, unsigned long, void* call_data) override {
    if (call_data == nullptr) return;
    std::istringstream lines(static_cast<const char*>(call_data));
    std::string line;
    while (std::getline(lines, line)) {
      // Drop VTK's "ERROR: In <source file>, line N" preamble; keep what went wrong.
      if (line.empty() || line.starts_with("ERROR: In") || line.starts_with("Warning: In")) {
        continue;
      }
      if (!messages.empty()) messages += "; ";
      messages += line;
    }
  }
  std::string messages;
};

fs::path temporary_path(const fs::path& path) {
  fs::path tmp = path;
  tmp += ".tmp";
  return tmp;
}

/// Writes `data` with `writer` as binary appended zlib-compressed XML to a temporary name, then
/// renames it to `path`.
void write_xml_atomically(vtkXMLWriter* writer, vtkDataObject* data, const fs::path& path) {
  vtkNew<MessageCollector> collector;
  writer->AddObserver(vtkCommand::ErrorEvent, collector);
  writer->AddObserver(vtkCommand::WarningEvent, collector);
  // The pipeline reports the writer's failure again with a dump of its request; it only repeats
  // what the writer said, so it is silenced and kept for when the writer said nothing.
  vtkNew<MessageCollector> pipeline;
  writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, pipeline);
  writer->GetExecutive()->AddObserver(vtkCommand::WarningEvent, pipeline);
  writer->SetInputData(data);
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();  // raw bytes, not base64
  writer->SetCompressorTypeToZLib();
  writer->SetHeaderTypeToUInt64();  // block sizes beyond 4 GiB
  const fs::path tmp = temporary_path(path);
  writer->SetFileName(tmp.string().c_str());
  const int written = writer->Write();
  if (written != 1 || writer->GetErrorCode() != 0 || !collector->messages.empty() ||
      !pipeline->messages.empty()) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    const std::string& reason =
        collector->messages.empty() ? pipeline->messages : collector->messages;
    throw core::IoError(path.string() + ": VTK could not write the file: " +
                        (reason.empty() ? std::string("no message") : reason) +
                        "; hint: check that the directory exists, is writable and has space");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw core::IoError(path.string() + ": cannot rename from " + tmp.string() + ": " +
                        ec.message());
  }
}

vtkSmartPointer<vtkIntArray> int_array(const char* name, vtkIdType count) {
  auto array = vtkSmartPointer<vtkIntArray>::New();
  array->SetName(name);
  array->SetNumberOfComponents(1);
  array->SetNumberOfTuples(count);
  return array;
}

vtkSmartPointer<vtkStringArray> string_array(const char* name,
                                             const std::vector<std::string>& values) {
  auto array = vtkSmartPointer<vtkStringArray>::New();
  array->SetName(name);
  array->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i) {
    array->SetValue(static_cast<vtkIdType>(i), values[i]);
  }
  return array;
}

/// Cells of equal size as one vtkCellArray; `rows` is #cells x `width`, `local` maps each entry
/// to a point index (identity when empty).
vtkSmartPointer<vtkCellArray> cell_array(const mesh::IndexMatrix& rows, int width,
                                         const std::vector<int>& local = {}) {
  const vtkIdType count = rows.rows();
  vtkNew<vtkIdTypeArray> offsets;
  offsets->SetNumberOfTuples(count + 1);
  vtkNew<vtkIdTypeArray> connectivity;
  connectivity->SetNumberOfTuples(count * width);
  for (vtkIdType c = 0; c <= count; ++c) offsets->SetValue(c, c * width);
  for (vtkIdType c = 0; c < count; ++c) {
    for (int k = 0; k < width; ++k) {
      const int node = rows(c, k);
      connectivity->SetValue(c * width + k, local.empty() ? node : local[node]);
    }
  }
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  cells->SetData(offsets, connectivity);
  return cells;
}

vtkSmartPointer<vtkPoints> point_coordinates(const mesh::NodeMatrix& nodes) {
  vtkNew<vtkDoubleArray> coordinates;
  coordinates->SetNumberOfComponents(3);
  coordinates->SetNumberOfTuples(nodes.rows());
  std::copy(nodes.data(), nodes.data() + nodes.size(), coordinates->GetPointer(0));
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetData(coordinates);
  return points;
}

vtkSmartPointer<vtkIntArray> region_array(const mesh::TetMesh& mesh) {
  auto region = int_array("region", mesh.tets.rows());
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    region->SetValue(t, core::index_of(mesh.tet_region[t]));
  }
  return region;
}

/// The volume grid without fields: points, cells, cell data `region`, field data `region_names`.
vtkSmartPointer<vtkUnstructuredGrid> volume_grid(const mesh::TetMesh& mesh) {
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  grid->SetPoints(point_coordinates(mesh.nodes));
  const int type = mesh.order == 1 ? VTK_TETRA : VTK_QUADRATIC_TETRA;
  grid->SetCells(type, cell_array(mesh.tets, mesh.nodes_per_tet()));
  grid->GetCellData()->AddArray(region_array(mesh));
  grid->GetFieldData()->AddArray(string_array("region_names", mesh.region_names));
  return grid;
}

std::string xml_escaped(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

/// Shortest text that reads back as the same double.
std::string round_trip_text(double value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

}  // namespace

void write_mesh_vtu(const mesh::TetMesh& mesh, const fs::path& path) {
  check_mesh(mesh);
  const auto grid = volume_grid(mesh);
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  write_xml_atomically(writer, grid, path);
}

void write_boundary_vtp(const mesh::TetMesh& mesh, const fs::path& path) {
  check_mesh(mesh);
  const Eigen::Index face_count = mesh.faces.rows();
  // Only the face corners become points, renumbered in order of first use.
  std::vector<int> local(mesh.nodes.rows(), -1);
  std::vector<int> used;
  for (Eigen::Index f = 0; f < face_count; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int node = mesh.faces(f, k);
      if (local[node] < 0) {
        local[node] = static_cast<int>(used.size());
        used.push_back(node);
      }
    }
  }
  mesh::NodeMatrix corners(static_cast<Eigen::Index>(used.size()), 3);
  auto node = int_array("node", static_cast<vtkIdType>(used.size()));
  for (std::size_t i = 0; i < used.size(); ++i) {
    corners.row(i) = mesh.nodes.row(used[i]);
    node->SetValue(static_cast<vtkIdType>(i), used[i]);
  }
  mesh::IndexMatrix triangles(face_count, 3);
  if (face_count > 0) triangles = mesh.faces.leftCols(3);

  auto group_id = int_array("group_id", face_count);
  auto interface = int_array("interface", face_count);
  auto region = int_array("region", face_count);
  std::vector<std::string> group_name(face_count);
  for (Eigen::Index f = 0; f < face_count; ++f) {
    const int group = core::index_of(mesh.face_group[f]);
    group_id->SetValue(f, group);
    group_name[f] = group >= 0 ? mesh.group_names[group] : std::string();
    interface->SetValue(f, mesh.face_other_tet[f] >= 0 ? 1 : 0);
    region->SetValue(f, core::index_of(mesh.tet_region[mesh.face_tet[f]]));
  }

  vtkNew<vtkPolyData> surface;
  surface->SetPoints(point_coordinates(corners));
  surface->SetPolys(cell_array(triangles, 3, local));
  surface->GetPointData()->AddArray(node);
  surface->GetCellData()->AddArray(group_id);
  surface->GetCellData()->AddArray(string_array("group_name", group_name));
  surface->GetCellData()->AddArray(interface);
  surface->GetCellData()->AddArray(region);
  surface->GetFieldData()->AddArray(string_array("group_names", mesh.group_names));
  vtkNew<vtkXMLPolyDataWriter> writer;
  write_xml_atomically(writer, surface, path);
}

void write_points_vtp(const mesh::TetMesh& mesh, const fs::path& path) {
  check_mesh(mesh);
  const auto count = static_cast<Eigen::Index>(mesh.points.size());
  mesh::NodeMatrix positions(count, 3);
  mesh::IndexMatrix vertices(count, 1);
  auto index = int_array("index", count);
  auto node = int_array("node", count);
  std::vector<std::string> ids(count);
  for (Eigen::Index p = 0; p < count; ++p) {
    positions.row(p) = mesh.points[p].position.transpose();
    vertices(p, 0) = static_cast<int>(p);
    index->SetValue(p, static_cast<int>(p));
    node->SetValue(p, mesh.points[p].node);
    ids[p] = mesh.points[p].id;
  }
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(point_coordinates(positions));
  cloud->SetVerts(cell_array(vertices, 1));
  cloud->GetPointData()->AddArray(string_array("id", ids));
  cloud->GetPointData()->AddArray(index);
  cloud->GetPointData()->AddArray(node);
  vtkNew<vtkXMLPolyDataWriter> writer;
  write_xml_atomically(writer, cloud, path);
}

void write_point_cloud_vtp(const fs::path& path, const std::vector<std::string>& ids,
                           const Eigen::MatrixX3d& positions,
                           const std::vector<NamedField>& fields) {
  const auto count = positions.rows();
  if (static_cast<Eigen::Index>(ids.size()) != count)
    throw core::DataError(path.string() + ": " + str(ids.size()) + " ids for " + str(count) +
                          " points");
  mesh::NodeMatrix xyz = positions;
  mesh::IndexMatrix vertices(count, 1);
  for (Eigen::Index p = 0; p < count; ++p) vertices(p, 0) = static_cast<int>(p);
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(point_coordinates(xyz));
  cloud->SetVerts(cell_array(vertices, 1));
  cloud->GetPointData()->AddArray(string_array("id", ids));
  for (const NamedField& f : fields) {
    if (f.values.size() != count * f.components)
      throw core::DataError(path.string() + ": field '" + f.name + "' has " + str(f.values.size()) +
                            " values, expected " + str(count * f.components));
    vtkNew<vtkDoubleArray> array;
    array->SetName(f.name.c_str());
    array->SetNumberOfComponents(f.components);
    array->SetNumberOfTuples(count);
    std::copy(f.values.data(), f.values.data() + f.values.size(), array->GetPointer(0));
    cloud->GetPointData()->AddArray(array);
  }
  vtkNew<vtkXMLPolyDataWriter> writer;
  write_xml_atomically(writer, cloud, path);
}

// ---------------------------------------------------------------------------------------------
// Field series

struct FieldSeriesWriter::Geometry {
  vtkSmartPointer<vtkPoints> points;
  vtkSmartPointer<vtkCellArray> cells;
  vtkSmartPointer<vtkUnsignedCharArray> types;
  vtkSmartPointer<vtkIntArray> region;
  vtkSmartPointer<vtkStringArray> region_names;
  Eigen::Index node_count = 0;
  Eigen::Index corner_count = 0;  /// > 0 when corner-only point fields can be expanded
  Eigen::Index tet_count = 0;
  /// per mid-edge node (index - corner_count): the two corners of its edge
  std::vector<std::array<int, 2>> edge_corners;
};

namespace {

/// The two corners of every mid-edge node, or empty when the mesh does not keep corners first.
std::vector<std::array<int, 2>> mid_edge_corners(const mesh::TetMesh& mesh) {
  const Eigen::Index corners = mesh.corner_count;
  const Eigen::Index mids = mesh.nodes.rows() - corners;
  if (mesh.order != 2 || corners <= 0 || mids <= 0) return {};
  std::vector<std::array<int, 2>> parents(mids, {-1, -1});
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    for (int e = 0; e < 6; ++e) {
      const int a = mesh.tets(t, kTetEdges[e].first);
      const int b = mesh.tets(t, kTetEdges[e].second);
      const int mid = mesh.tets(t, 4 + e);
      if (a >= corners || b >= corners || mid < corners) return {};
      parents[mid - corners] = {a, b};
    }
  }
  for (const auto& p : parents) {
    if (p[0] < 0) return {};  // a node after the corners that is no mid-edge node
  }
  return parents;
}

void check_field_names(const std::vector<NamedField>& fields, const char* kind) {
  std::set<std::string> seen;
  for (const NamedField& field : fields) {
    if (field.name.empty()) {
      throw core::DataError(std::string("a ") + kind +
                            " field has an empty name; hint: name it with its unit, e.g. "
                            "temperature_degC");
    }
    if (!seen.insert(field.name).second) {
      throw core::DataError(std::string(kind) + " field '" + field.name +
                            "' is given twice in one step");
    }
  }
}

}  // namespace

FieldSeriesWriter::FieldSeriesWriter(const mesh::TetMesh& mesh, fs::path dir, std::string stem)
    : geometry_(std::make_unique<Geometry>()), dir_(std::move(dir)), stem_(std::move(stem)) {
  check_mesh(mesh);
  if (stem_.empty() || stem_.find_first_of("/\\") != std::string::npos) {
    throw core::IoError("field series stem '" + stem_ +
                        "': expected a non-empty file name without a directory");
  }
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) {
    throw core::IoError(dir_.string() +
                        ": cannot create the field series directory: " + ec.message());
  }
  Geometry& g = *geometry_;
  g.points = point_coordinates(mesh.nodes);
  g.cells = cell_array(mesh.tets, mesh.nodes_per_tet());
  g.types = vtkSmartPointer<vtkUnsignedCharArray>::New();
  g.types->SetNumberOfTuples(mesh.tets.rows());
  g.types->FillValue(mesh.order == 1 ? VTK_TETRA : VTK_QUADRATIC_TETRA);
  g.region = region_array(mesh);
  g.region_names = string_array("region_names", mesh.region_names);
  g.node_count = mesh.nodes.rows();
  g.tet_count = mesh.tets.rows();
  g.edge_corners = mid_edge_corners(mesh);
  g.corner_count = g.edge_corners.empty() ? 0 : mesh.corner_count;
}

FieldSeriesWriter::~FieldSeriesWriter() = default;

namespace {

/// A point field as a VTK array over every node: a field given at the corners only (a linear
/// field on an order-2 mesh) gets its mid-edge values halfway along each edge (`edge_corners`).
vtkSmartPointer<vtkDoubleArray> point_field_array(
    const NamedField& field, Eigen::Index node_count, Eigen::Index corner_count,
    const std::vector<std::array<int, 2>>& edge_corners) {
  const int c = field.components;
  const bool full = c >= 1 && field.values.size() == node_count * c;
  const bool corners_only = c >= 1 && corner_count > 0 && field.values.size() == corner_count * c;
  if (!full && !corners_only) {
    throw core::DataError(
        "point field '" + field.name + "' has " + str(field.values.size()) + " values with " +
        str(c) + " components: expected #nodes * components = " + str(node_count * c) +
        (corner_count > 0 ? " (or #corners * components = " + str(corner_count * c) + ")"
                          : std::string()) +
        "; hint: values are entity-major (x0 y0 z0 x1 ...)");
  }
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName(field.name.c_str());
  array->SetNumberOfComponents(c);
  array->SetNumberOfTuples(node_count);
  double* out = array->GetPointer(0);
  std::copy(field.values.data(), field.values.data() + field.values.size(), out);
  if (!full) {
    for (std::size_t m = 0; m < edge_corners.size(); ++m) {
      const auto [a, b] = edge_corners[m];
      for (int k = 0; k < c; ++k) {
        out[(corner_count + m) * c + k] = 0.5 * (out[a * c + k] + out[b * c + k]);
      }
    }
  }
  return array;
}

/// A cell field as a VTK array over every tet.
vtkSmartPointer<vtkDoubleArray> cell_field_array(const NamedField& field, Eigen::Index tet_count) {
  const int c = field.components;
  if (field.name == "region") {
    throw core::DataError(
        "cell field 'region' clashes with the region ids every step carries; hint: rename it");
  }
  if (c < 1 || field.values.size() != tet_count * c) {
    throw core::DataError("cell field '" + field.name + "' has " + str(field.values.size()) +
                          " values with " + str(c) + " components: expected #tets * " +
                          "components = " + str(tet_count * std::max(c, 1)));
  }
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName(field.name.c_str());
  array->SetNumberOfComponents(c);
  array->SetNumberOfTuples(tet_count);
  std::copy(field.values.data(), field.values.data() + field.values.size(), array->GetPointer(0));
  return array;
}

/// Throws DataError unless `time_s` is finite and after `previous_s` (when there is one).
void check_step_time(double time_s, std::optional<double> previous_s) {
  if (!std::isfinite(time_s)) {
    throw core::DataError("field series step time = " + round_trip_text(time_s) +
                          " s: expected a finite time");
  }
  if (previous_s && !(time_s > *previous_s)) {
    throw core::DataError("field series step time = " + round_trip_text(time_s) +
                          " s: expected a time after the previous step (" +
                          round_trip_text(*previous_s) + " s); hint: add steps in increasing time");
  }
}

}  // namespace

fs::path FieldSeriesWriter::add_step(double time_s, const std::vector<NamedField>& point_fields,
                                     const std::vector<NamedField>& cell_fields) {
  check_step_time(time_s, steps_.empty() ? std::nullopt : std::optional(steps_.back().time_s));
  check_field_names(point_fields, "point");
  check_field_names(cell_fields, "cell");
  const Geometry& g = *geometry_;

  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(g.points);
  grid->SetCells(g.types, g.cells);
  grid->GetCellData()->AddArray(g.region);
  vtkNew<vtkFieldData> field_data;
  field_data->AddArray(g.region_names);
  vtkNew<vtkDoubleArray> time_value;  // ParaView reads a lone .vtu's time from this array
  time_value->SetName("TimeValue");
  time_value->InsertNextValue(time_s);
  field_data->AddArray(time_value);
  grid->SetFieldData(field_data);
  for (const NamedField& field : point_fields)
    grid->GetPointData()->AddArray(
        point_field_array(field, g.node_count, g.corner_count, g.edge_corners));
  for (const NamedField& field : cell_fields)
    grid->GetCellData()->AddArray(cell_field_array(field, g.tet_count));

  std::array<char, 16> number{};
  std::snprintf(number.data(), number.size(), "%04zu", steps_.size());
  const fs::path path = dir_ / (stem_ + "_" + number.data() + ".vtu");
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  write_xml_atomically(writer, grid, path);
  steps_.push_back({time_s, path});
  return path;
}

fs::path FieldSeriesWriter::finish() {
  const fs::path path = dir_ / (stem_ + ".pvd");
  write_file_atomically(path, pvd_collection(steps_));
  return path;
}

std::string pvd_collection(const std::vector<SeriesStep>& steps) {
  const char* byte_order =
      std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
  std::string text = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" " +
                     std::string("byte_order=\"") + byte_order + "\">\n  <Collection>\n";
  for (const SeriesStep& step : steps) {
    text += "    <DataSet timestep=\"" + round_trip_text(step.time_s) +
            "\" group=\"\" part=\"0\" file=\"" + xml_escaped(step.file.filename().string()) +
            "\"/>\n";
  }
  text += "  </Collection>\n</VTKFile>\n";
  return text;
}

}  // namespace tt::io
