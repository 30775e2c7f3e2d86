// SB-1 as `thermotwin mesh` makes it, checked without trusting mesh_report.json: the case is read,
// meshed and written with the mesh command's own pieces, the VTK files are read back with VTK's
// XML readers, and every figure is recomputed from them against the spec
// (docs/SB-1-spindle-box.md): exact named vertices, regions, volumes, conforming bearing
// interfaces, quality, boundary group areas and the 10-node ordering of VTK's quadratic tetra.
#include <gtest/gtest.h>
#include <unistd.h>
#include <vtkCellData.h>
#include <vtkCellTypes.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkQuadraticTetra.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "io/case_reader.hpp"
#include "io/vtk_out.hpp"
#include "mesh/mesher.hpp"

namespace tt::mesh::test {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

/// The SB-1 mesh as read back from mesh.vtu, boundary.vtp and points.vtp.
struct Sb1Files {
  core::CaseSpec spec;
  std::vector<Vector3d> nodes;            /// from mesh.vtu [m]
  int cell_type = 0;                      /// VTK cell type of every cell
  std::vector<std::array<int, 10>> tets;  /// mesh.vtu connectivity
  std::vector<int> region;                /// per tet
  std::vector<std::string> region_names;  /// mesh.vtu field data
  bool float64_points = false;            /// mesh.vtu stores doubles

  std::vector<std::array<Vector3d, 3>> boundary;  /// boundary.vtp triangles [m]
  std::vector<int> boundary_group;                /// per triangle
  std::vector<std::string> group_names;           /// boundary.vtp field data

  std::vector<std::string> point_ids;     /// points.vtp
  std::vector<Vector3d> point_positions;  /// points.vtp [m]
  std::vector<int> point_nodes;           /// points.vtp
};

std::vector<std::string> strings(vtkFieldData* data, const char* name) {
  auto* a = vtkStringArray::SafeDownCast(data->GetAbstractArray(name));
  std::vector<std::string> out;
  if (a)
    for (vtkIdType i = 0; i < a->GetNumberOfValues(); ++i) out.push_back(a->GetValue(i));
  return out;
}

Sb1Files read_back() {
  Sb1Files s;
  s.spec = io::read_case(fs::path(TT_SOURCE_DIR) / "cases" / "sb1.toml");
  const TetMesh mesh = mesh_case(s.spec);
  const fs::path dir = fs::temp_directory_path() / ("tt_mesh_sb1_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  io::write_mesh_vtu(mesh, dir / "mesh.vtu");
  io::write_boundary_vtp(mesh, dir / "boundary.vtp");
  io::write_points_vtp(mesh, dir / "points.vtp");

  vtkNew<vtkXMLUnstructuredGridReader> grid_reader;
  grid_reader->SetFileName((dir / "mesh.vtu").c_str());
  grid_reader->Update();
  vtkUnstructuredGrid* grid = grid_reader->GetOutput();
  s.float64_points = grid->GetPoints()->GetDataType() == VTK_DOUBLE;
  for (vtkIdType i = 0; i < grid->GetNumberOfPoints(); ++i) {
    double x[3];
    grid->GetPoint(i, x);
    s.nodes.emplace_back(x[0], x[1], x[2]);
  }
  vtkDataArray* region = grid->GetCellData()->GetArray("region");
  s.cell_type = grid->GetNumberOfCells() > 0 ? grid->GetCellType(0) : 0;
  for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c) {
    if (grid->GetCellType(c) != s.cell_type) s.cell_type = -1;
    vtkIdType n;
    const vtkIdType* ids;
    grid->GetCellPoints(c, n, ids);
    std::array<int, 10> t{};
    for (vtkIdType k = 0; k < std::min<vtkIdType>(n, 10); ++k) t[k] = static_cast<int>(ids[k]);
    s.tets.push_back(t);
    s.region.push_back(region ? static_cast<int>(region->GetTuple1(c)) : -1);
  }
  s.region_names = strings(grid->GetFieldData(), "region_names");

  vtkNew<vtkXMLPolyDataReader> boundary_reader;
  boundary_reader->SetFileName((dir / "boundary.vtp").c_str());
  boundary_reader->Update();
  vtkPolyData* boundary = boundary_reader->GetOutput();
  vtkDataArray* group = boundary->GetCellData()->GetArray("group_id");
  for (vtkIdType c = 0; c < boundary->GetNumberOfCells(); ++c) {
    vtkIdType n;
    const vtkIdType* ids;
    boundary->GetCellPoints(c, n, ids);
    std::array<Vector3d, 3> tri;
    for (int k = 0; k < 3; ++k) {
      double x[3];
      boundary->GetPoint(ids[k], x);
      tri[k] = Vector3d(x[0], x[1], x[2]);
    }
    s.boundary.push_back(tri);
    s.boundary_group.push_back(group ? static_cast<int>(group->GetTuple1(c)) : -2);
  }
  s.group_names = strings(boundary->GetFieldData(), "group_names");

  vtkNew<vtkXMLPolyDataReader> points_reader;
  points_reader->SetFileName((dir / "points.vtp").c_str());
  points_reader->Update();
  vtkPolyData* points = points_reader->GetOutput();
  auto* ids = vtkStringArray::SafeDownCast(points->GetPointData()->GetAbstractArray("id"));
  vtkDataArray* node = points->GetPointData()->GetArray("node");
  for (vtkIdType i = 0; i < points->GetNumberOfPoints(); ++i) {
    double x[3];
    points->GetPoint(i, x);
    s.point_positions.emplace_back(x[0], x[1], x[2]);
    s.point_ids.push_back(ids ? ids->GetValue(i) : "");
    s.point_nodes.push_back(node ? static_cast<int>(node->GetTuple1(i)) : -1);
  }
  fs::remove_all(dir);
  return s;
}

const Sb1Files& sb1() {
  static const Sb1Files files = read_back();
  return files;
}

int region_of(const std::string& name) {
  const auto& names = sb1().region_names;
  return static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
}

double tet_volume(const std::array<int, 10>& t) {
  const auto& x = sb1().nodes;
  return (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).dot(x[t[3]] - x[t[0]]) / 6.0;
}

double triangle_area(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  return 0.5 * (b - a).cross(c - a).norm();
}

// The spec's geometry, analytically: `band` > 0 grows every body by that much, < 0 shrinks it.
constexpr double kBore = 0.060, kShaft = 0.045;
double axis_distance(const Vector3d& p) {
  return std::hypot(p.x(), p.y() - 0.18);
}
bool in_housing(const Vector3d& p, double band) {
  return p.x() >= -0.16 - band && p.x() <= 0.16 + band && p.y() >= -band && p.y() <= 0.30 + band &&
         p.z() >= -band && p.z() <= 0.48 + band && axis_distance(p) >= kBore - band;
}
bool in_shaft(const Vector3d& p, double band) {
  return axis_distance(p) <= kShaft + band && p.z() >= -0.04 - band && p.z() <= 0.58 + band;
}
bool in_bearing(const Vector3d& p, double z0, double band) {
  const double r = axis_distance(p);
  return r >= kShaft - band && r <= kBore + band && p.z() >= z0 - band && p.z() <= z0 + 0.05 + band;
}
bool in_body(const std::string& name, const Vector3d& p, double band) {
  if (name == "housing") return in_housing(p, band);
  if (name == "shaft") return in_shaft(p, band);
  if (name == "rear_bearing") return in_bearing(p, 0.040, band);
  if (name == "front_bearing") return in_bearing(p, 0.400, band);
  ADD_FAILURE() << "unknown body " << name;
  return false;
}

/// SB-1's named points as the spec defines them: C-54 face by face, z, transverse; TCP; Z1, Z2.
std::map<std::string, Vector3d> spec_points() {
  std::map<std::string, Vector3d> out;
  const double zs[] = {0.04, 0.12, 0.20, 0.28, 0.36, 0.44};
  int id = 1;
  auto add = [&](const Vector3d& p) {
    const std::string number = std::to_string(id++);
    out[(number.size() < 2 ? "T0" : "T") + number] = p;
  };
  for (double z : zs)
    for (double x : {-0.08, 0.0, 0.08}) add(Vector3d(x, 0.30, z));
  for (double side : {-0.16, 0.16})
    for (double z : zs)
      for (double y : {0.08, 0.16, 0.24}) add(Vector3d(side, y, z));
  out["TCP"] = Vector3d(0.0, 0.18, 0.58);
  out["Z1"] = Vector3d(0.0, 0.18, 0.50);
  out["Z2"] = Vector3d(0.0, 0.18, 0.57);
  return out;
}

TEST(Sb1Mesh, FilesReadBackAsAQuadraticTetMeshOfFourBodies) {
  const auto& s = sb1();
  EXPECT_TRUE(s.float64_points);
  EXPECT_EQ(s.cell_type, VTK_QUADRATIC_TETRA);
  EXPECT_GT(s.tets.size(), 20000u);
  EXPECT_EQ(s.region_names,
            (std::vector<std::string>{"housing", "shaft", "rear_bearing", "front_bearing"}));
  for (const auto& t : s.tets) ASSERT_GT(tet_volume(t), 0.0);
}

TEST(Sb1Mesh, NamedPointsAreVerticesAtExactlyTheirSpecCoordinates) {
  const auto& s = sb1();
  const auto expected = spec_points();
  ASSERT_EQ(expected.size(), 57u);
  ASSERT_EQ(s.point_ids.size(), 57u);
  std::map<std::string, int> seen;
  for (size_t i = 0; i < s.point_ids.size(); ++i) {
    const std::string& id = s.point_ids[i];
    ASSERT_EQ(expected.count(id), 1u) << id;
    ++seen[id];
    const Vector3d& want = expected.at(id);
    const int node = s.point_nodes[i];
    ASSERT_GE(node, 0) << id;
    ASSERT_LT(node, static_cast<int>(s.nodes.size())) << id;
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(s.point_positions[i][k], want[k]) << id << " in points.vtp";
      EXPECT_EQ(s.nodes[node][k], want[k]) << id << " as a vertex of mesh.vtu";
    }
    // A vertex of the mesh: some tet has it as a corner.
    bool corner = false;
    for (const auto& t : s.tets)
      if (std::find(t.begin(), t.begin() + 4, node) != t.begin() + 4) {
        corner = true;
        break;
      }
    EXPECT_TRUE(corner) << id;
  }
  EXPECT_EQ(seen.size(), 57u);
}

TEST(Sb1Mesh, EveryTetLiesInTheBodyOfItsRegion) {
  const auto& s = sb1();
  // Faceting moves a circle's boundary by at most r (1 - cos(pi/48)) + (r_f - r) ~ 2e-4 m.
  const double band = 2.5e-4;
  int wrong = 0;
  for (size_t t = 0; t < s.tets.size(); ++t) {
    Vector3d c = Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += s.nodes[s.tets[t][k]] / 4.0;
    const std::string& mine = s.region_names.at(s.region[t]);
    bool ok = in_body(mine, c, band);
    for (const auto& other : s.region_names)
      if (other != mine && in_body(other, c, -band)) ok = false;
    if (!ok && ++wrong <= 5)
      ADD_FAILURE() << "tet " << t << " of " << mine << " has its centroid at (" << c.transpose()
                    << ")";
  }
  EXPECT_EQ(wrong, 0);
}

TEST(Sb1Mesh, BodyVolumesAreWithinHalfAPercentOfExact) {
  const auto& s = sb1();
  const double pi = M_PI;
  const std::map<std::string, double> exact = {
      {"housing", 0.32 * 0.30 * 0.48 - pi * kBore * kBore * 0.48},
      {"shaft", pi * kShaft * kShaft * 0.62},
      {"rear_bearing", pi * (kBore * kBore - kShaft * kShaft) * 0.05},
      {"front_bearing", pi * (kBore * kBore - kShaft * kShaft) * 0.05}};
  std::map<std::string, double> volume;
  for (size_t t = 0; t < s.tets.size(); ++t)
    volume[s.region_names.at(s.region[t])] += tet_volume(s.tets[t]);
  for (const auto& [name, v] : exact) EXPECT_NEAR(volume[name], v, 0.005 * v) << name;
}

TEST(Sb1Mesh, BearingInterfacesConformAndHaveTheSpecAreas) {
  const auto& s = sb1();
  // Faces by their sorted corner nodes: two tets share a face only if they share its nodes.
  std::map<std::array<int, 3>, std::vector<int>> tets_of_face;
  constexpr int kFaces[4][3] = {{0, 1, 2}, {0, 1, 3}, {1, 2, 3}, {0, 2, 3}};
  for (size_t t = 0; t < s.tets.size(); ++t)
    for (const auto& f : kFaces) {
      std::array<int, 3> key = {s.tets[t][f[0]], s.tets[t][f[1]], s.tets[t][f[2]]};
      std::sort(key.begin(), key.end());
      tets_of_face[key].push_back(static_cast<int>(t));
    }
  const int shaft = region_of("shaft"), housing = region_of("housing");
  for (const std::string bearing : {"rear_bearing", "front_bearing"}) {
    const int b = region_of(bearing);
    double with_shaft = 0, with_housing = 0, inner_wall = 0, outer_wall = 0;
    for (const auto& [key, tets] : tets_of_face) {
      ASSERT_LE(tets.size(), 2u);
      const bool mine = s.region[tets[0]] == b || (tets.size() == 2 && s.region[tets[1]] == b);
      if (!mine) continue;
      const Vector3d &p = s.nodes[key[0]], &q = s.nodes[key[1]], &r = s.nodes[key[2]];
      const double area = triangle_area(p, q, r);
      if (tets.size() == 2 && s.region[tets[0]] != s.region[tets[1]]) {
        const int other = s.region[tets[0]] == b ? s.region[tets[1]] : s.region[tets[0]];
        if (other == shaft) with_shaft += area;
        if (other == housing) with_housing += area;
      }
      // The bearing's own cylindrical walls, found by geometry: faces of a bearing tet with no
      // bearing tet across them. Conforming means every such face is matched by node sharing.
      if (tets.size() == 2 && s.region[tets[0]] == s.region[tets[1]]) continue;
      auto on = [&](double radius) {
        for (const Vector3d* x : {&p, &q, &r})
          if (std::abs(axis_distance(*x) - radius) > 2.5e-4) return false;
        return true;
      };
      if (on(kShaft)) inner_wall += area;
      if (on(kBore)) outer_wall += area;
    }
    const double inner = 2 * M_PI * kShaft * 0.05, outer = 2 * M_PI * kBore * 0.05;
    EXPECT_NEAR(with_shaft, inner, 0.01 * inner) << bearing;
    EXPECT_NEAR(with_housing, outer, 0.01 * outer) << bearing;
    EXPECT_NEAR(with_shaft, inner_wall, 1e-12)
        << bearing << ": a wall face has no shaft tet across it";
    EXPECT_NEAR(with_housing, outer_wall, 1e-12)
        << bearing << ": a wall face has no housing tet across it";
  }
}

TEST(Sb1Mesh, SmallestDihedralAngleIsAtLeastEightDegrees) {
  const auto& s = sb1();
  double worst = 180;
  constexpr int kFaces[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  for (const auto& t : s.tets) {
    Vector3d n[4];
    for (int f = 0; f < 4; ++f) {
      const Vector3d& a = s.nodes[t[kFaces[f][0]]];
      n[f] = (s.nodes[t[kFaces[f][1]]] - a).cross(s.nodes[t[kFaces[f][2]]] - a).normalized();
    }
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        worst = std::min(worst, std::acos(std::clamp(-n[i].dot(n[j]), -1.0, 1.0)) * 180 / M_PI);
  }
  EXPECT_GE(worst, 8.0);
}

TEST(Sb1Mesh, BoundaryGroupAreasMatchTheSpec) {
  const auto& s = sb1();
  const double pi = M_PI, bore_hole = pi * kBore * kBore;
  const std::map<std::string, double> exact = {
      {"bed_contact", 0.32 * 0.48},
      {"housing_outer", 0.32 * 0.48 + 2 * 0.30 * 0.48 + 2 * (0.32 * 0.30 - bore_hole)},
      {"air_gap", 2 * pi * (kBore + kShaft) * (0.48 - 0.10)},
      {"shaft_outside", 2 * pi * kShaft * (0.04 + 0.10) + 2 * pi * kShaft * kShaft},
      {"bearing_seals", 4 * pi * (kBore * kBore - kShaft * kShaft)}};
  ASSERT_EQ(s.group_names.size(), 5u);
  std::vector<double> area(s.group_names.size(), 0.0);
  for (size_t f = 0; f < s.boundary.size(); ++f)
    if (s.boundary_group[f] >= 0)
      area.at(s.boundary_group[f]) +=
          triangle_area(s.boundary[f][0], s.boundary[f][1], s.boundary[f][2]);
  for (const auto& [name, a] : exact) {
    const auto it = std::find(s.group_names.begin(), s.group_names.end(), name);
    ASSERT_NE(it, s.group_names.end()) << name;
    EXPECT_NEAR(area[it - s.group_names.begin()], a, 0.005 * a) << name;
  }
}

// The 10-node tet against VTK's quadratic tetra: mid-edge nodes on VTK's edges, and VTK's own
// shape functions reproduce the straight-sided tet's affine map (a permutation of the mid-edge
// nodes would break it away from the symmetric centre).
TEST(Sb1Mesh, TenNodeTetsFollowVtkQuadraticTetraOrdering) {
  const auto& s = sb1();
  ASSERT_EQ(s.cell_type, VTK_QUADRATIC_TETRA);
  constexpr int kEdges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  for (const auto& t : s.tets)
    for (int e = 0; e < 6; ++e) {
      const Vector3d mid = 0.5 * (s.nodes[t[kEdges[e][0]]] + s.nodes[t[kEdges[e][1]]]);
      ASSERT_LT((s.nodes[t[4 + e]] - mid).norm(), 1e-14) << "edge " << e;
    }
  vtkNew<vtkQuadraticTetra> cell;
  double centre[3];
  cell->GetParametricCenter(centre);
  for (size_t i = 0; i < s.tets.size(); i += s.tets.size() / 50) {
    const auto& t = s.tets[i];
    const Vector3d x0 = s.nodes[t[0]];
    const Vector3d centroid = (x0 + s.nodes[t[1]] + s.nodes[t[2]] + s.nodes[t[3]]) / 4.0;
    for (const std::array<double, 3> r : {std::array<double, 3>{centre[0], centre[1], centre[2]},
                                          std::array<double, 3>{0.1, 0.2, 0.3}}) {
      double w[10];
      vtkQuadraticTetra::InterpolationFunctions(r.data(), w);
      Vector3d x = Vector3d::Zero();
      for (int k = 0; k < 10; ++k) x += w[k] * s.nodes[t[k]];
      const Vector3d affine = x0 + r[0] * (s.nodes[t[1]] - x0) + r[1] * (s.nodes[t[2]] - x0) +
                              r[2] * (s.nodes[t[3]] - x0);
      EXPECT_LT((x - affine).norm(), 1e-14) << "tet " << i;
      if (r[0] == centre[0]) {
        EXPECT_LT((x - centroid).norm(), 1e-14) << "tet " << i;
      }
    }
  }
}

}  // namespace
}  // namespace tt::mesh::test
