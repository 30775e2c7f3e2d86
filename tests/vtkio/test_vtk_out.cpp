// The VTK writers read back with VTK's own XML readers: counts, cell types, connectivity, region
// ids, named-point ids, field values, and the compressed appended encoding.
#include <gtest/gtest.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUtilities.h>

#include <fstream>
#include <sstream>

#include "core/errors.hpp"
#include "io/vtk_out.hpp"
#include "tiny_mesh.hpp"

namespace tt::io {
namespace {

namespace fs = std::filesystem;

vtkSmartPointer<vtkUnstructuredGrid> read_vtu(const fs::path& path) {
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(path.string().c_str());
  reader->Update();
  return reader->GetOutput();
}

vtkSmartPointer<vtkPolyData> read_vtp(const fs::path& path) {
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.string().c_str());
  reader->Update();
  return reader->GetOutput();
}

std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The XML header of a VTK file with appended data: everything before the raw bytes.
std::string xml_header(const fs::path& path) {
  const std::string text = file_text(path);
  return text.substr(0, text.find("<AppendedData"));
}

void expect_compressed_appended(const fs::path& path) {
  const std::string header = xml_header(path);
  EXPECT_NE(header.find("compressor=\"vtkZLibDataCompressor\""), std::string::npos) << path;
  EXPECT_NE(header.find("format=\"appended\""), std::string::npos) << path;
  EXPECT_EQ(header.find("format=\"ascii\""), std::string::npos) << path;
  EXPECT_NE(file_text(path).find("<AppendedData encoding=\"raw\">"), std::string::npos) << path;
}

bool has_temporary_files(const fs::path& dir) {
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() == ".tmp") return true;
  }
  return false;
}

void expect_grid_matches_mesh(vtkUnstructuredGrid* grid, const mesh::TetMesh& mesh) {
  ASSERT_EQ(grid->GetNumberOfPoints(), mesh.nodes.rows());
  ASSERT_EQ(grid->GetNumberOfCells(), mesh.tets.rows());
  const int type = mesh.order == 1 ? VTK_TETRA : VTK_QUADRATIC_TETRA;
  for (Eigen::Index p = 0; p < mesh.nodes.rows(); ++p) {
    double x[3];
    grid->GetPoint(p, x);
    for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(x[k], mesh.nodes(p, k)) << "point " << p;
  }
  vtkNew<vtkIdList> ids;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    EXPECT_EQ(grid->GetCellType(t), type);
    grid->GetCellPoints(t, ids);
    ASSERT_EQ(ids->GetNumberOfIds(), mesh.nodes_per_tet());
    for (int k = 0; k < mesh.nodes_per_tet(); ++k) {
      EXPECT_EQ(ids->GetId(k), mesh.tets(t, k)) << "tet " << t << " node " << k;
    }
  }
  auto* region = vtkIntArray::SafeDownCast(grid->GetCellData()->GetAbstractArray("region"));
  ASSERT_NE(region, nullptr);
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    EXPECT_EQ(region->GetValue(t), core::index_of(mesh.tet_region[t]));
  }
}

TEST(MeshVtu, LinearTetsReadBackWithRegions) {
  const auto dir = test::scratch_dir("mesh_linear");
  const auto mesh = test::two_tets();
  write_mesh_vtu(mesh, dir / "mesh.vtu");
  const auto grid = read_vtu(dir / "mesh.vtu");
  expect_grid_matches_mesh(grid, mesh);
  auto* names =
      vtkStringArray::SafeDownCast(grid->GetFieldData()->GetAbstractArray("region_names"));
  ASSERT_NE(names, nullptr);
  ASSERT_EQ(names->GetNumberOfValues(), 2);
  EXPECT_EQ(names->GetValue(1), "spindle");
  expect_compressed_appended(dir / "mesh.vtu");
  EXPECT_FALSE(has_temporary_files(dir));
}

TEST(MeshVtu, QuadraticTetsKeepMidEdgeNodes) {
  const auto dir = test::scratch_dir("mesh_quadratic");
  const auto mesh = test::quadratic(test::two_tets());
  ASSERT_EQ(mesh.nodes.rows(), 14);  // 5 corners + 9 distinct edges
  write_mesh_vtu(mesh, dir / "mesh.vtu");
  const auto grid = read_vtu(dir / "mesh.vtu");
  expect_grid_matches_mesh(grid, mesh);
  // Node 4 of a quadratic tetra sits halfway along edge (0,1): VTK's ordering survived.
  vtkNew<vtkIdList> ids;
  grid->GetCellPoints(1, ids);
  double a[3], b[3], m[3];
  grid->GetPoint(ids->GetId(0), a);
  grid->GetPoint(ids->GetId(1), b);
  grid->GetPoint(ids->GetId(4), m);
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(m[k], 0.5 * (a[k] + b[k]));
  expect_compressed_appended(dir / "mesh.vtu");
}

TEST(MeshVtu, InconsistentMeshIsRejected) {
  const auto dir = test::scratch_dir("mesh_bad");
  auto mesh = test::two_tets();
  mesh.tet_region.pop_back();
  EXPECT_THROW(write_mesh_vtu(mesh, dir / "mesh.vtu"), core::MeshError);
  mesh = test::two_tets();
  mesh.tets(1, 3) = 7;
  try {
    write_mesh_vtu(mesh, dir / "mesh.vtu");
    FAIL() << "a node index past the end was accepted";
  } catch (const core::MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("= 7"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "mesh.vtu"));
}

TEST(MeshVtu, UnwritableDirectoryThrowsIoErrorAndLeavesNothing) {
  const auto dir = test::scratch_dir("mesh_unwritable");
  const auto target = dir / "missing" / "mesh.vtu";
  testing::internal::CaptureStderr();  // VTK's complaints belong in the exception, not on stderr
  try {
    write_mesh_vtu(test::two_tets(), target);
    ADD_FAILURE() << "writing into a missing directory succeeded";
  } catch (const core::IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(target.string()), std::string::npos) << what;
    EXPECT_NE(what.find("vtkXMLUnstructuredGridWriter"), std::string::npos) << what;
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_FALSE(fs::exists(target));
  EXPECT_FALSE(has_temporary_files(dir));
}

TEST(BoundaryVtp, FacesGroupsAndInterfaces) {
  const auto dir = test::scratch_dir("boundary_linear");
  const auto mesh = test::two_tets();
  write_boundary_vtp(mesh, dir / "boundary.vtp");
  const auto surface = read_vtp(dir / "boundary.vtp");
  ASSERT_EQ(surface->GetNumberOfPolys(), 7);
  ASSERT_EQ(surface->GetNumberOfPoints(), 5);
  auto* node = vtkIntArray::SafeDownCast(surface->GetPointData()->GetAbstractArray("node"));
  auto* group = vtkIntArray::SafeDownCast(surface->GetCellData()->GetAbstractArray("group_id"));
  auto* name = vtkStringArray::SafeDownCast(surface->GetCellData()->GetAbstractArray("group_name"));
  auto* interface =
      vtkIntArray::SafeDownCast(surface->GetCellData()->GetAbstractArray("interface"));
  auto* region = vtkIntArray::SafeDownCast(surface->GetCellData()->GetAbstractArray("region"));
  ASSERT_TRUE(node && group && name && interface && region);
  const std::vector<int> groups = {0, -1, -1, -1, 1, 1, -1};
  const std::vector<std::string> names = {"base", "", "", "", "bore", "bore", ""};
  int interface_count = 0;
  vtkNew<vtkIdList> ids;
  for (int f = 0; f < 7; ++f) {
    EXPECT_EQ(surface->GetCellType(f), VTK_TRIANGLE);
    EXPECT_EQ(group->GetValue(f), groups[f]) << "face " << f;
    EXPECT_EQ(name->GetValue(f), names[f]) << "face " << f;
    EXPECT_EQ(region->GetValue(f), f < 4 ? 0 : 1) << "face " << f;
    interface_count += interface->GetValue(f);
    surface->GetCellPoints(f, ids);
    ASSERT_EQ(ids->GetNumberOfIds(), 3);
    for (int k = 0; k < 3; ++k) {
      // The point behind each corner is the mesh node the face names, at its coordinates.
      const vtkIdType p = ids->GetId(k);
      EXPECT_EQ(node->GetValue(p), mesh.faces(f, k));
      double x[3];
      surface->GetPoint(p, x);
      for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(x[c], mesh.nodes(mesh.faces(f, k), c));
    }
  }
  EXPECT_EQ(interface->GetValue(3), 1);
  EXPECT_EQ(interface_count, 1);
  auto* all_names =
      vtkStringArray::SafeDownCast(surface->GetFieldData()->GetAbstractArray("group_names"));
  ASSERT_NE(all_names, nullptr);
  EXPECT_EQ(all_names->GetNumberOfValues(), 2);
  expect_compressed_appended(dir / "boundary.vtp");
}

TEST(BoundaryVtp, QuadraticFacesBecomeCornerTriangles) {
  const auto dir = test::scratch_dir("boundary_quadratic");
  const auto mesh = test::quadratic(test::two_tets());
  write_boundary_vtp(mesh, dir / "boundary.vtp");
  const auto surface = read_vtp(dir / "boundary.vtp");
  ASSERT_EQ(surface->GetNumberOfPolys(), 7);
  EXPECT_EQ(surface->GetNumberOfPoints(), 5);  // mid-edge nodes are left out
  auto* node = vtkIntArray::SafeDownCast(surface->GetPointData()->GetAbstractArray("node"));
  ASSERT_NE(node, nullptr);
  for (vtkIdType p = 0; p < surface->GetNumberOfPoints(); ++p) {
    EXPECT_LT(node->GetValue(p), mesh.corner_count);
  }
  vtkNew<vtkIdList> ids;
  surface->GetCellPoints(4, ids);
  ASSERT_EQ(ids->GetNumberOfIds(), 3);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(node->GetValue(ids->GetId(k)), mesh.faces(4, k));
}

TEST(PointsVtp, NamedPointsCarryIdIndexAndNode) {
  const auto dir = test::scratch_dir("points");
  const auto mesh = test::two_tets();
  write_points_vtp(mesh, dir / "points.vtp");
  const auto cloud = read_vtp(dir / "points.vtp");
  ASSERT_EQ(cloud->GetNumberOfPoints(), 3);
  ASSERT_EQ(cloud->GetNumberOfVerts(), 3);
  auto* id = vtkStringArray::SafeDownCast(cloud->GetPointData()->GetAbstractArray("id"));
  auto* index = vtkIntArray::SafeDownCast(cloud->GetPointData()->GetAbstractArray("index"));
  auto* node = vtkIntArray::SafeDownCast(cloud->GetPointData()->GetAbstractArray("node"));
  ASSERT_TRUE(id && index && node);
  for (int p = 0; p < 3; ++p) {
    EXPECT_EQ(id->GetValue(p), mesh.points[p].id);
    EXPECT_EQ(index->GetValue(p), p);
    EXPECT_EQ(node->GetValue(p), mesh.points[p].node);
    double x[3];
    cloud->GetPoint(p, x);
    for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(x[k], mesh.points[p].position(k));
  }
  EXPECT_EQ(node->GetValue(2), -1);
  expect_compressed_appended(dir / "points.vtp");
}

/// Point or cell array `name` of `grid` as a flat vector, empty when missing.
std::vector<double> array_values(vtkDataSetAttributes* data, const char* name) {
  vtkDataArray* array = data->GetArray(name);
  if (array == nullptr) return {};
  std::vector<double> values;
  for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i) {
    for (int c = 0; c < array->GetNumberOfComponents(); ++c) {
      values.push_back(array->GetComponent(i, c));
    }
  }
  return values;
}

TEST(FieldSeries, StepsAndCollectionReadBack) {
  const auto dir = test::scratch_dir("series");
  const auto mesh = test::quadratic(test::two_tets());
  const Eigen::Index n = mesh.nodes.rows();
  FieldSeriesWriter writer(mesh, dir / "out");
  const std::vector<double> times = {0.0, 600.0, 1800.5};
  for (std::size_t s = 0; s < times.size(); ++s) {
    NamedField temperature{"temperature_degC", 1, Eigen::VectorXd::LinSpaced(n, 20.0, 30.0)};
    temperature.values.array() += static_cast<double>(s);
    NamedField displacement{"displacement_m", 3, Eigen::VectorXd::Constant(3 * n, 0.0)};
    for (Eigen::Index i = 0; i < n; ++i) displacement.values(3 * i + 1) = 1e-6 * i + s;
    NamedField stress{"von_mises_Pa", 1, Eigen::Vector2d(1e6, 2e6 + s)};
    const auto file = writer.add_step(times[s], {temperature, displacement}, {stress});
    EXPECT_EQ(file.parent_path(), dir / "out");

    const auto grid = read_vtu(file);
    expect_grid_matches_mesh(grid, mesh);
    const auto t = array_values(grid->GetPointData(), "temperature_degC");
    ASSERT_EQ(t.size(), static_cast<std::size_t>(n));
    for (Eigen::Index i = 0; i < n; ++i) EXPECT_DOUBLE_EQ(t[i], temperature.values(i));
    const auto u = array_values(grid->GetPointData(), "displacement_m");
    ASSERT_EQ(u.size(), static_cast<std::size_t>(3 * n));
    EXPECT_EQ(grid->GetPointData()->GetArray("displacement_m")->GetNumberOfComponents(), 3);
    EXPECT_DOUBLE_EQ(u[3 * 5 + 1], 5e-6 + s);
    EXPECT_DOUBLE_EQ(u[3 * 5 + 0], 0.0);
    const auto vm = array_values(grid->GetCellData(), "von_mises_Pa");
    ASSERT_EQ(vm.size(), 2u);
    EXPECT_DOUBLE_EQ(vm[1], 2e6 + s);
    vtkDataArray* tv = grid->GetFieldData()->GetArray("TimeValue");
    ASSERT_NE(tv, nullptr);
    EXPECT_DOUBLE_EQ(tv->GetComponent(0, 0), times[s]);
    expect_compressed_appended(file);
  }
  const auto pvd = writer.finish();
  EXPECT_EQ(pvd, dir / "out" / "fields.pvd");
  ASSERT_EQ(writer.steps().size(), 3u);

  vtkSmartPointer<vtkXMLDataElement> root;
  root.TakeReference(vtkXMLUtilities::ReadElementFromFile(pvd.string().c_str()));
  ASSERT_NE(root, nullptr) << "fields.pvd is not well-formed XML";
  EXPECT_STREQ(root->GetName(), "VTKFile");
  EXPECT_STREQ(root->GetAttribute("type"), "Collection");
  vtkXMLDataElement* collection = root->FindNestedElementWithName("Collection");
  ASSERT_NE(collection, nullptr);
  ASSERT_EQ(collection->GetNumberOfNestedElements(), 3);
  for (int s = 0; s < 3; ++s) {
    vtkXMLDataElement* dataset = collection->GetNestedElement(s);
    EXPECT_STREQ(dataset->GetName(), "DataSet");
    double timestep = -1.0;
    ASSERT_TRUE(dataset->GetScalarAttribute("timestep", timestep));
    EXPECT_DOUBLE_EQ(timestep, times[s]);
    const std::string file = dataset->GetAttribute("file");
    EXPECT_EQ(file, writer.steps()[s].file.filename().string());
    EXPECT_TRUE(fs::exists(dir / "out" / file)) << file;
  }
  EXPECT_FALSE(has_temporary_files(dir / "out"));
}

TEST(FieldSeries, StepsCarryOnlyTheirOwnArrays) {
  const auto dir = test::scratch_dir("series_arrays");
  const auto mesh = test::two_tets();
  FieldSeriesWriter writer(mesh, dir, "run");
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(5);
  const auto first = writer.add_step(0.0, {{"temperature_degC", 1, ones}});
  const auto second = writer.add_step(1.0, {{"temperature_rise_K", 1, 2 * ones}});
  EXPECT_EQ(first.filename(), "run_0000.vtu");
  EXPECT_EQ(second.filename(), "run_0001.vtu");
  const auto grid = read_vtu(second);
  EXPECT_EQ(grid->GetPointData()->GetArray("temperature_degC"), nullptr);
  ASSERT_NE(grid->GetPointData()->GetArray("temperature_rise_K"), nullptr);
  EXPECT_EQ(grid->GetPointData()->GetNumberOfArrays(), 1);
  EXPECT_EQ(grid->GetCellData()->GetNumberOfArrays(), 1);  // region
  ASSERT_NE(grid->GetCellData()->GetArray("region"), nullptr);
  EXPECT_EQ(writer.finish().filename(), "run.pvd");
}

TEST(FieldSeries, CornerFieldOnQuadraticMeshIsInterpolatedAlongEdges) {
  const auto dir = test::scratch_dir("series_corner");
  const auto mesh = test::quadratic(test::two_tets());
  FieldSeriesWriter writer(mesh, dir);
  // Linear in x at the corners, so the mid-edge values must be linear in x too.
  Eigen::VectorXd corner_values(mesh.corner_count);
  for (int i = 0; i < mesh.corner_count; ++i) corner_values(i) = 20.0 + 3.0 * mesh.nodes(i, 0);
  const auto file = writer.add_step(0.0, {{"temperature_degC", 1, corner_values}});
  const auto t = array_values(read_vtu(file)->GetPointData(), "temperature_degC");
  ASSERT_EQ(t.size(), static_cast<std::size_t>(mesh.nodes.rows()));
  for (Eigen::Index i = 0; i < mesh.nodes.rows(); ++i) {
    EXPECT_NEAR(t[i], 20.0 + 3.0 * mesh.nodes(i, 0), 1e-12) << "node " << i;
  }
}

TEST(FieldSeries, BadStepsAreRejected) {
  const auto dir = test::scratch_dir("series_bad");
  const auto mesh = test::two_tets();
  FieldSeriesWriter writer(mesh, dir);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(5);
  try {
    writer.add_step(0.0, {{"displacement_m", 3, ones}});
    FAIL() << "a vector field with too few values was accepted";
  } catch (const core::DataError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("displacement_m"), std::string::npos) << what;
    EXPECT_NE(what.find("15"), std::string::npos) << what;
  }
  EXPECT_THROW(writer.add_step(0.0, {}, {{"von_mises_Pa", 1, ones}}), core::DataError);
  EXPECT_THROW(writer.add_step(0.0, {}, {{"region", 1, Eigen::Vector2d(1, 2)}}), core::DataError);
  EXPECT_THROW(writer.add_step(0.0, {{"T", 1, ones}, {"T", 1, ones}}), core::DataError);
  writer.add_step(10.0, {{"T", 1, ones}});
  EXPECT_THROW(writer.add_step(10.0, {{"T", 1, ones}}), core::DataError);
  EXPECT_THROW(writer.add_step(5.0, {{"T", 1, ones}}), core::DataError);
  EXPECT_EQ(writer.steps().size(), 1u);
  // A corner-only field is meaningless on a linear mesh with one node set.
  EXPECT_THROW(writer.add_step(20.0, {{"T", 1, Eigen::VectorXd::Ones(4)}}), core::DataError);
}

TEST(FieldSeries, CollectionTextEscapesNamesAndKeepsFullPrecision) {
  const std::string text = pvd_collection({{0.1, "a&b_0000.vtu"}, {1.0 / 3.0, "x_0001.vtu"}});
  EXPECT_NE(text.find("file=\"a&amp;b_0000.vtu\""), std::string::npos) << text;
  EXPECT_NE(text.find("timestep=\"0.1\""), std::string::npos) << text;
  EXPECT_NE(text.find("timestep=\"0.3333333333333333\""), std::string::npos) << text;
  vtkSmartPointer<vtkXMLDataElement> root;
  root.TakeReference(vtkXMLUtilities::ReadElementFromString(text.c_str()));
  ASSERT_NE(root, nullptr);
  EXPECT_EQ(root->FindNestedElementWithName("Collection")->GetNumberOfNestedElements(), 2);
}

}  // namespace
}  // namespace tt::io
