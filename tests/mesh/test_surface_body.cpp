// Bodies read from surface files (STL, OFF, PLY) through CGAL: valid solids mesh with their exact
// volume and their named points as exact vertices; every defect is rejected with a message that
// names the file, the body and what is wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/errors.hpp"
#include "io/case_reader.hpp"
#include "mesh/cgal/surface_body.hpp"
#include "mesh/mesher.hpp"
#include "mesh_fixtures.hpp"

namespace tt::mesh::test {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

std::string surface_body_toml(const std::string& name, const std::string& file, double max_edge,
                              const std::string& unit = "m") {
  return "[[bodies]]\nname = \"" + name +
         "\"\nmaterial = \"steel\"\nmax_edge = " + number(max_edge) +
         "\nadd = [ { surface = { file = \"" + file + "\", unit = \"" + unit + "\" } } ]\n";
}

std::string box_body_toml(const std::string& name, const Vector3d& lo, const Vector3d& hi,
                          double max_edge, const std::string& subtract = "") {
  std::string s = "[[bodies]]\nname = \"" + name +
                  "\"\nmaterial = \"steel\"\nmax_edge = " + number(max_edge) +
                  "\nadd = [ { box = { min = [" + number(lo.x()) + ", " + number(lo.y()) + ", " +
                  number(lo.z()) + "], max = [" + number(hi.x()) + ", " + number(hi.y()) + ", " +
                  number(hi.z()) + "] } } ]\n";
  if (!subtract.empty()) s += "subtract = [ " + subtract + " ]\n";
  return s;
}

std::string point_toml(const std::string& id, const Vector3d& p, const std::string& on = "") {
  std::string s = "  { id = \"" + id + "\", position = [" + number(p.x()) + ", " + number(p.y()) +
                  ", " + number(p.z()) + "]";
  if (!on.empty()) s += ", on = \"" + on + "\"";
  return s + " },\n";
}

double region_volume(const TetMesh& m, int region) {
  const auto v = tet_volumes(m);
  double sum = 0;
  for (int t = 0; t < m.tets.rows(); ++t)
    if (core::index_of(m.tet_region[t]) == region) sum += v[t];
  return sum;
}

/// Runs `f`, expects a GeometryError and returns its message.
template <class F>
std::string geometry_error(F f) {
  try {
    f();
  } catch (const core::GeometryError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a GeometryError";
  return "";
}

TEST(SurfaceBody, CubeInMillimetresMeshesWithExactVolumeAndExactPoints) {
  TempDir dir;
  dir.write("cube.stl", stl_text(cube(Vector3d(10, 20, 30), 40)));  // [mm]
  const Vector3d corner(0.05, 0.06, 0.07), on_face(0.025, 0.045, 0.07),
      on_diagonal(0.03, 0.04, 0.07), on_crease(0.03, 0.02, 0.07), inside(0.03, 0.04, 0.05);
  const std::string points = point_toml("C", corner, "outside") +
                             point_toml("F", on_face, "outside") +
                             point_toml("E", on_diagonal, "outside") +
                             point_toml("K", on_crease, "outside") + point_toml("I", inside);
  const auto spec = io::read_case(dir.write(
      "case.toml", small_case(surface_body_toml("cube", "cube.stl", 0.012, "mm"), points)));
  const TetMesh m = mesh_case(spec);

  ASSERT_GT(m.tets.rows(), 20);
  EXPECT_NEAR(region_volume(m, 0), 6.4e-5, 1e-9 * 6.4e-5);
  const MeshReport r = mesh_report(m, spec);
  ASSERT_EQ(r.bodies.size(), 1u);
  EXPECT_NEAR(r.bodies[0].exact_volume, 6.4e-5, 1e-12 * 6.4e-5);
  EXPECT_NEAR(r.bodies[0].volume, r.bodies[0].exact_volume, 1e-9 * 6.4e-5);
  EXPECT_NEAR(r.group_areas.at(0), 6 * 0.04 * 0.04, 1e-9);
  EXPECT_GT(r.min_dihedral_deg, 5.0);

  // Named points are vertices at exactly their coordinates: a file vertex, points inside a face,
  // on a triangle edge inside a face and on an edge between faces, and an interior point.
  ASSERT_EQ(m.points.size(), 5u);
  for (const auto& p : m.points) {
    ASSERT_GE(p.node, 0) << p.id;
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m.nodes(p.node, k), p.position[k]) << p.id;
  }
  // Every boundary face lies on the cube's surface.
  for (int f = 0; f < m.faces.rows(); ++f) {
    int planes = 0;
    for (int axis = 0; axis < 3; ++axis)
      for (double x : {0.01 + 0.01 * axis, 0.05 + 0.01 * axis}) {
        bool all = true;
        for (int k = 0; k < 3; ++k) all = all && std::abs(m.nodes(m.faces(f, k), axis) - x) < 1e-12;
        planes += all ? 1 : 0;
      }
    EXPECT_EQ(planes, 1) << "face " << f;
  }
}

TEST(SurfaceBody, FacetedCylinderFromOffMeshesWithItsPolygonVolume) {
  TempDir dir;
  dir.write("cyl.off", off_text(prism(Vector2d(0.0, 0.0), 0.05, 0.0, 0.2, 40)));
  const auto spec =
      io::read_case(dir.write("case.toml", small_case(surface_body_toml("cyl", "cyl.off", 0.02))));
  const TetMesh m = mesh_case(spec);
  const double exact = prism_volume(0.05, 0.0, 0.2, 40);
  EXPECT_NEAR(region_volume(m, 0), exact, 1e-9 * exact);
  EXPECT_NEAR(mesh_report(m, spec).bodies[0].exact_volume, exact, 1e-12 * exact);
  // Every boundary face lies on a cap or on a side plane of the prism.
  int off_surface = 0;
  for (int f = 0; f < m.faces.rows(); ++f) {
    Vector3d x[3];
    for (int k = 0; k < 3; ++k) x[k] = m.nodes.row(m.faces(f, k)).transpose();
    const Vector3d normal = (x[1] - x[0]).cross(x[2] - x[0]).normalized();
    bool on = true;
    for (const auto& c : x)
      on = on && (std::abs(normal.z()) > 1 - 1e-12
                      ? std::min(std::abs(c.z()), std::abs(c.z() - 0.2)) < 1e-12
                      : std::abs(normal.dot(c) - 0.05 * std::cos(M_PI / 40)) < 1e-12);
    if (!on && ++off_surface <= 3)
      ADD_FAILURE() << "face " << f << " with normal " << normal.transpose();
  }
  EXPECT_EQ(off_surface, 0);
  EXPECT_GT(min_dihedral_deg(m), 5.0);
  const double side = 40 * 2 * 0.05 * std::sin(M_PI / 40) * 0.2;
  const double caps = 2 * exact / 0.2;
  EXPECT_NEAR(mesh_report(m, spec).group_areas.at(0), side + caps, 1e-9);
}

TEST(SurfaceBody, PlyCubeMeshes) {
  TempDir dir;
  dir.write("cube.ply", ply_text(cube(Vector3d(0, 0, 0), 0.1)));
  const auto spec = io::read_case(
      dir.write("case.toml", small_case(surface_body_toml("cube", "cube.ply", 0.04))));
  EXPECT_NEAR(region_volume(mesh_case(spec), 0), 1e-3, 1e-12);
}

TEST(SurfaceBody, InwardOrientedCubeIsTurnedOutward) {
  TempDir dir;
  const auto file = dir.write("inward.stl", stl_text(reversed(cube(Vector3d(0, 0, 0), 0.1))));
  const cgal::SurfaceSolid s = cgal::surface_solid(file, 1.0, "body 'inward'");
  EXPECT_NEAR(s.volume, 1e-3, 1e-15);
  double signed_volume = 0;  // divergence theorem: positive when the normals point out
  for (const auto& t : s.surface.triangles)
    signed_volume +=
        s.surface.vertices[t[0]].dot(s.surface.vertices[t[1]].cross(s.surface.vertices[t[2]])) /
        6.0;
  EXPECT_NEAR(signed_volume, 1e-3, 1e-15);
  EXPECT_TRUE((s.inside_point.array() > 0.0).all() && (s.inside_point.array() < 0.1).all());

  const auto spec = io::read_case(
      dir.write("case.toml", small_case(surface_body_toml("inward", "inward.stl", 0.04))));
  EXPECT_NEAR(region_volume(mesh_case(spec), 0), 1e-3, 1e-12);
}

/// The GeometryError that meshing a case with one surface body from `soup_text` in `file` gives.
std::string surface_error(const std::string& file, const std::string& soup_text) {
  TempDir dir;
  dir.write(file, soup_text);
  const auto spec =
      io::read_case(dir.write("case.toml", small_case(surface_body_toml("part", file, 0.05))));
  return geometry_error([&] { mesh_case(spec); });
}

TEST(SurfaceBody, OpenSurfaceIsRejected) {
  const std::string msg =
      surface_error("open_cube.stl", stl_text(without_face(cube(Vector3d(0, 0, 0), 0.1), 2)));
  EXPECT_NE(msg.find("open_cube.stl"), std::string::npos) << msg;
  EXPECT_NE(msg.find("body 'part'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("open: 4 edges"), std::string::npos) << msg;
  EXPECT_NE(msg.find("Hint"), std::string::npos) << msg;
}

TEST(SurfaceBody, SelfIntersectingSurfaceIsRejected) {
  const Soup two = merged(cube(Vector3d(0, 0, 0), 0.1), cube(Vector3d(0.05, 0.05, 0.05), 0.1));
  const std::string msg = surface_error("crossed.off", off_text(two));
  EXPECT_NE(msg.find("crossed.off"), std::string::npos) << msg;
  EXPECT_NE(msg.find("intersects itself"), std::string::npos) << msg;
}

TEST(SurfaceBody, TwoShellsAreRejected) {
  const Soup two = merged(cube(Vector3d(0, 0, 0), 0.1), cube(Vector3d(0.3, 0, 0), 0.1));
  const std::string msg = surface_error("two.stl", stl_text(two));
  EXPECT_NE(msg.find("2 separate shells"), std::string::npos) << msg;
}

TEST(SurfaceBody, UnreadableFileIsRejected) {
  const std::string msg = surface_error("junk.ply", "this is not a PLY file\n");
  EXPECT_NE(msg.find("junk.ply"), std::string::npos) << msg;
  EXPECT_NE(msg.find("a PLY file starts with the line 'ply'"), std::string::npos) << msg;
  const std::string stl = surface_error("junk.stl", "this is not an STL file\n");
  EXPECT_NE(stl.find("could not read"), std::string::npos) << stl;
}

TEST(SurfaceBody, FarFlungVertexIsRejectedBeforeTheGeometryChecks) {
  const std::string msg = surface_error(
      "far.off",
      "OFF\n4 4 0\n0 0 0\n10 3.3e44 0\n0 10 0\n0 0 10\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n");
  EXPECT_NE(msg.find("far.off"), std::string::npos) << msg;
  EXPECT_NE(msg.find("vertex 1 has coordinate y"), std::string::npos) << msg;
}

TEST(SurfaceBody, SurfaceMixedWithPrimitivesInOneBodyIsRejected) {
  TempDir dir;
  dir.write("cube.stl", stl_text(cube(Vector3d(0, 0, 0), 0.1)));
  const std::string body =
      "[[bodies]]\nname = \"mixed\"\nmaterial = \"steel\"\nmax_edge = 0.05\n"
      "add = [ { surface = { file = \"cube.stl\" } }, { box = { min = [0.2, 0, 0], max = [0.3, "
      "0.1, 0.1] } } ]\n";
  const auto spec = io::read_case(dir.write("case.toml", small_case(body)));
  const std::string msg = geometry_error([&] { mesh_case(spec); });
  EXPECT_NE(msg.find("body 'mixed'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("2 add and 0 subtract"), std::string::npos) << msg;
}

TEST(SurfaceBody, SurfaceOverlappingABoxIsRejected) {
  TempDir dir;
  dir.write("cube.stl", stl_text(cube(Vector3d(0.05, 0.05, 0.05), 0.1)));
  const std::string bodies =
      box_body_toml("block", Vector3d(0, 0, 0), Vector3d(0.1, 0.1, 0.1), 0.05) +
      surface_body_toml("part", "cube.stl", 0.05);
  const auto spec = io::read_case(dir.write("case.toml", small_case(bodies)));
  const std::string msg = geometry_error([&] { mesh_case(spec); });
  EXPECT_NE(msg.find("body 'part'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("cube.stl"), std::string::npos) << msg;
  EXPECT_NE(msg.find("overlaps or touches body 'block'"), std::string::npos) << msg;
}

TEST(SurfaceBody, TouchingSurfacesAreRejected) {
  TempDir dir;
  dir.write("a.stl", stl_text(cube(Vector3d(0, 0, 0), 0.1)));
  dir.write("b.stl", stl_text(cube(Vector3d(0.1, 0.02, 0.02), 0.05)));
  const std::string bodies =
      surface_body_toml("a", "a.stl", 0.05) + surface_body_toml("b", "b.stl", 0.05);
  const auto spec = io::read_case(dir.write("case.toml", small_case(bodies)));
  const std::string msg = geometry_error([&] { mesh_case(spec); });
  EXPECT_NE(msg.find("body 'a'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("overlaps or touches body 'b'"), std::string::npos) << msg;
}

TEST(SurfaceBody, NamedPointOutsideEveryBodyIsRejected) {
  TempDir dir;
  dir.write("cube.stl", stl_text(cube(Vector3d(0, 0, 0), 0.1)));
  const auto spec =
      io::read_case(dir.write("case.toml", small_case(surface_body_toml("part", "cube.stl", 0.05),
                                                      point_toml("P", Vector3d(0.2, 0.05, 0.05)))));
  const std::string msg = geometry_error([&] { mesh_case(spec); });
  EXPECT_NE(msg.find("'P'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("outside every body"), std::string::npos) << msg;
}

// A surface body inside a housing's bore, clear of it, next to a second surface body outside:
// both mesh with their exact volume beside the extruded housing, and the bore's hole point does
// not erase the body that fills most of the bore.
TEST(SurfaceBody, SurfaceBodyInsideASubtractedBoreMeshesBesideTheHousing) {
  TempDir dir;
  const int n = 32;
  dir.write("plug.off", off_text(prism(Vector2d(0.0, 0.1), 0.0585, 0.01, 0.29, n)));
  dir.write("lug.stl", stl_text(cube(Vector3d(0.15, 0.0, 0.1), 0.05)));
  const std::string bore = "{ cylinder = { axis = [0.0, 0.1], radius = 0.06, z = [0.0, 0.3] } }";
  const std::string bodies =
      box_body_toml("housing", Vector3d(-0.1, 0, 0), Vector3d(0.1, 0.2, 0.3), 0.04, bore) +
      surface_body_toml("plug", "plug.off", 0.03) + surface_body_toml("lug", "lug.stl", 0.03);
  const std::string points = point_toml("H", Vector3d(0.0, 0.2, 0.15), "outside") +
                             point_toml("P", Vector3d(0.0, 0.1, 0.15)) +
                             point_toml("L", Vector3d(0.175, 0.025, 0.15), "outside");
  const auto spec = io::read_case(
      dir.write("case.toml", small_case(bodies, points, "m", "circle_segments = 32\n")));
  const TetMesh m = mesh_case(spec);
  const MeshReport r = mesh_report(m, spec);
  const double plug = prism_volume(0.0585, 0.01, 0.29, n);
  const double housing = 0.2 * 0.2 * 0.3 - M_PI * 0.06 * 0.06 * 0.3;  // faceting keeps the area
  EXPECT_NEAR(region_volume(m, 0), housing, 1e-9);
  EXPECT_NEAR(region_volume(m, 1), plug, 1e-9 * plug);
  EXPECT_NEAR(region_volume(m, 2), 1.25e-4, 1e-9 * 1.25e-4);
  EXPECT_NEAR(r.bodies[1].exact_volume, plug, 1e-12 * plug);
  // No interface: the bodies stand apart.
  for (int f = 0; f < m.faces.rows(); ++f) EXPECT_LT(m.face_other_tet[f], 0);
  for (const auto& p : m.points)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m.nodes(p.node, k), p.position[k]) << p.id;
}

TEST(SurfaceBody, PrimitiveAndSurfaceSolidsMeetOnlyWhenTheyShareAPoint) {
  auto surface = [](const Soup& s) {
    cgal::TriangleSurface t;
    t.vertices = s.vertices;
    for (const auto& f : s.faces)
      for (size_t k = 1; k + 1 < f.size(); ++k) t.triangles.push_back({f[0], f[k], f[k + 1]});
    return t;
  };
  const auto big = surface(cube(Vector3d(0, 0, 0), 1.0));
  const auto small = surface(cube(Vector3d(0.25, 0.25, 0.25), 0.5));
  const auto apart = surface(cube(Vector3d(2, 0, 0), 1.0));
  const auto touching = surface(cube(Vector3d(1, 0, 0), 1.0));
  EXPECT_TRUE(cgal::solids_meet(small, big));  // nested: the volumes overlap
  EXPECT_TRUE(cgal::solids_meet(touching, big));
  EXPECT_FALSE(cgal::solids_meet(apart, big));
  EXPECT_TRUE(cgal::solid_strictly_inside(small, big));
  EXPECT_FALSE(cgal::solid_strictly_inside(touching, big));
  EXPECT_FALSE(cgal::solid_strictly_inside(big, small));

  const auto where = cgal::locate_points(big,
                                         {Vector3d(1, 1, 1), Vector3d(0.5, 0.5, 1.0),
                                          Vector3d(0.5, 0.5, 0.5), Vector3d(0.5, 0.5, 1.5)},
                                         1e-9);
  using Kind = cgal::PointLocation::Kind;
  EXPECT_EQ(where[0].kind, Kind::vertex);
  EXPECT_EQ(big.vertices[where[0].index], Vector3d(1, 1, 1));
  EXPECT_EQ(where[1].kind, Kind::triangle);
  EXPECT_EQ(where[2].kind, Kind::inside);
  EXPECT_EQ(where[3].kind, Kind::outside);
}

}  // namespace
}  // namespace tt::mesh::test
