// The only translation unit that includes CGAL. Surfaces are read as polygon soups, repaired and
// oriented, turned into a Surface_mesh, and checked in the order in which a defect makes the later
// checks meaningless: closed, triangles, not self-intersecting, one shell, outward, volume.
#include "mesh/cgal/surface_body.hpp"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/intersection.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <sstream>

#include "core/errors.hpp"
#include "mesh/cgal/surface_file_check.hpp"

namespace tt::mesh::cgal {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using FaceIndex = Mesh::Face_index;
using Tree =
    CGAL::AABB_tree<CGAL::AABB_traits<Kernel, CGAL::AABB_face_graph_triangle_primitive<Mesh>>>;
using Inside = CGAL::Side_of_triangle_mesh<Mesh, Kernel>;

Eigen::Vector3d eigen(const Point& p) {
  return {p.x(), p.y(), p.z()};
}
Point point(const Eigen::Vector3d& p) {
  return {p.x(), p.y(), p.z()};
}

/// The surface as a CGAL mesh whose vertex and face indices are those of `s`.
Mesh mesh_of(const TriangleSurface& s) {
  Mesh m;
  std::vector<Mesh::Vertex_index> v;
  v.reserve(s.vertices.size());
  for (const auto& p : s.vertices) v.push_back(m.add_vertex(point(p)));
  for (const auto& t : s.triangles)
    if (m.add_face(v[t[0]], v[t[1]], v[t[2]]) == Mesh::null_face())
      throw core::GeometryError("internal: a primitive's surface is not 2-manifold");
  return m;
}

/// The mesh as plain vertices and triangles, in the mesh's own index order (it has no removals).
TriangleSurface surface_of(const Mesh& m) {
  TriangleSurface s;
  for (auto v : m.vertices()) s.vertices.push_back(eigen(m.point(v)));
  for (auto f : m.faces()) {
    std::array<int, 3> t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) t[k++] = static_cast<int>(v.idx());
    s.triangles.push_back(t);
  }
  return s;
}

/// A point midway between the centroid of a large triangle and the next surface hit by the inward
/// ray from it: inside, and as far from the surface as such a point can cheaply be.
Eigen::Vector3d inside_point_of(const Mesh& m, double diagonal, const std::string& prefix) {
  Tree tree(faces(m).first, faces(m).second, m);
  const Inside side(m);
  std::vector<std::pair<double, FaceIndex>> by_area;
  for (auto f : m.faces()) by_area.push_back({PMP::face_area(f, m), f});
  const size_t tries = std::min<size_t>(by_area.size(), 24);
  std::partial_sort(by_area.begin(), by_area.begin() + tries, by_area.end(),
                    [](const auto& a, const auto& b) { return a.first > b.first; });
  double best_clearance = 0;
  Eigen::Vector3d best = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < tries; ++i) {
    const FaceIndex f = by_area[i].second;
    std::array<Eigen::Vector3d, 3> c;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) c[k++] = eigen(m.point(v));
    const Eigen::Vector3d centroid = (c[0] + c[1] + c[2]) / 3.0;
    const Eigen::Vector3d inward = -(c[1] - c[0]).cross(c[2] - c[0]).normalized();
    std::vector<Tree::Intersection_and_primitive_id<Kernel::Ray_3>::Type> hits;
    tree.all_intersections(Kernel::Ray_3(point(centroid), point(centroid + inward)),
                           std::back_inserter(hits));
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& [where, face] : hits) {
      if (face == f) continue;
      if (const Point* p = boost::get<Point>(&where)) {
        const double t = (eigen(*p) - centroid).norm();
        if (t > 1e-12 * diagonal) nearest = std::min(nearest, t);
      }
    }
    if (!std::isfinite(nearest)) continue;
    const Eigen::Vector3d candidate = centroid + 0.5 * nearest * inward;
    if (side(point(candidate)) != CGAL::ON_BOUNDED_SIDE) continue;
    const double clearance = std::sqrt(tree.squared_distance(point(candidate)));
    if (clearance > best_clearance) best_clearance = clearance, best = candidate;
  }
  if (best_clearance <= 1e-9 * diagonal)
    throw core::GeometryError(prefix +
                              "no point clearly inside the surface was found; it "
                              "encloses (almost) no space. Hint: check the file.");
  return best;
}

/// The file's polygon soup. CGAL 5.5's OFF and PLY readers trust the file (docs/reliability.md,
/// F3 to F11): OFF is read by our own strict reader, and a PLY header is checked before CGAL reads
/// the file. False when CGAL's reader fails; `reader_said` holds what it printed.
bool read_soup(const std::filesystem::path& file, const std::string& prefix,
               std::vector<Point>& points, std::vector<std::vector<std::size_t>>& polygons,
               std::string& reader_said) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const auto refuse = [&](const std::string& problem) {
    return core::GeometryError(prefix + problem +
                               ". Hint: export the surface again, as ASCII OFF, "
                               "STL or a PLY with float coordinates.");
  };
  if (extension == ".off" || extension == ".ply") {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw core::GeometryError(prefix + "cannot open the file");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (extension == ".off") {
      OffReading off = read_off(text);
      if (!off.problem.empty()) throw refuse(off.problem);
      for (const auto& p : off.soup.points) points.emplace_back(p[0], p[1], p[2]);
      polygons = std::move(off.soup.polygons);
      return true;
    }
    if (const auto problem = ply_header_problem(text)) throw refuse(*problem);
  }
  std::ostringstream said;  // CGAL's readers report format errors on std::cerr
  bool read = false;
  std::streambuf* cerr_buffer = std::cerr.rdbuf(said.rdbuf());
  try {
    read = CGAL::IO::read_polygon_soup(file.string(), points, polygons);
  } catch (...) {
    read = false;
  }
  std::cerr.rdbuf(cerr_buffer);
  reader_said = said.str();
  return read;
}

/// A polygon soup in m.
struct Soup {
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
};

/// The file's polygons, scaled to m and split into triangles; refuses an unreadable file, bad
/// indices, coordinates beyond 10 km and polygons that cannot be split.
Soup triangle_soup(const std::filesystem::path& file, double scale, const std::string& prefix) {
  Soup soup;
  auto& [points, polygons] = soup;
  std::string said;
  const bool read = read_soup(file, prefix, points, polygons, said);
  if (!read || polygons.empty()) {
    while (!said.empty() && std::isspace(static_cast<unsigned char>(said.back()))) said.pop_back();
    throw core::GeometryError(prefix + "could not read any polygon" +
                              (said.empty() ? "" : " (the reader said: " + said + ")") +
                              ". Hint: the file must be an ASCII or binary STL, an OFF or a PLY "
                              "surface.");
  }
  if (const auto problem = soup_problem(polygons, points.size()))
    throw core::GeometryError(prefix + *problem + ". Hint: check the exporter's settings.");
  for (auto& p : points) p = Point(scale * p.x(), scale * p.y(), scale * p.z());
  // A machine part lies within kilometres of its origin; beyond that, a coordinate is a unit or
  // export error, and CGAL's predicates are not made for it.
  constexpr double kFarthest = 1e4;  // m
  for (std::size_t v = 0; v < points.size(); ++v)
    for (int k = 0; k < 3; ++k)
      if (!(std::abs(points[v][k]) <= kFarthest)) {
        std::ostringstream msg;
        msg << prefix << "vertex " << v << " has coordinate "
            << "xyz"[k] << " = " << points[v][k] << " m, beyond " << kFarthest
            << " m. Hint: check the file and its length unit.";
        throw core::GeometryError(msg.str());
      }
  std::vector<std::array<double, 3>> xyz;
  xyz.reserve(points.size());
  for (const auto& p : points) xyz.push_back({p.x(), p.y(), p.z()});
  Triangulation split = fan_triangulated(xyz, polygons);
  if (!split.problem.empty())
    throw core::GeometryError(prefix + split.problem +
                              ". Hint: export triangles (most exporters have a setting).");
  polygons = std::move(split.triangles);
  return soup;
}

/// The triangle soup repaired, oriented consistently and made a mesh; refuses a soup that is not
/// a 2-manifold surface.
Mesh triangle_mesh(Soup soup, const std::string& prefix) {
  auto& [points, polygons] = soup;
  PMP::repair_polygon_soup(points, polygons);
  if (!PMP::orient_polygon_soup(points, polygons))
    throw core::GeometryError(prefix +
                              "the surface is not 2-manifold (an edge is shared by more "
                              "than two triangles, or shells touch at a vertex). Hint: "
                              "export one watertight solid per file.");
  if (polygons.empty() || !PMP::is_polygon_soup_a_polygon_mesh(polygons))
    throw core::GeometryError(prefix +
                              "the polygons do not form a surface. Hint: export one "
                              "watertight solid per file.");
  Mesh m;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, m);
  if (!CGAL::is_triangle_mesh(m))  // the soup was split into triangles above
    throw core::GeometryError(prefix +
                              "internal: the surface is not all triangles after splitting");
  m.collect_garbage();
  return m;
}

/// Refuses a mesh that does not bound one solid: open, self-intersecting or of several shells.
void check_one_closed_shell(Mesh& m, const std::string& prefix) {
  if (!CGAL::is_closed(m)) {
    int border = 0;
    for (auto h : m.halfedges()) border += m.is_border(h) ? 1 : 0;
    throw core::GeometryError(prefix + "the surface is open: " + std::to_string(border) +
                              " edges bound only one triangle, expected 0. Hint: close the holes "
                              "(fill the missing faces) before exporting.");
  }
  if (PMP::does_self_intersect(m)) {
    std::vector<std::pair<FaceIndex, FaceIndex>> pairs;
    PMP::self_intersections(m, std::back_inserter(pairs));
    throw core::GeometryError(prefix + "the surface intersects itself (" +
                              std::to_string(pairs.size()) +
                              " pairs of triangles cross). Hint: "
                              "union the parts into one solid before exporting.");
  }
  // One shell: a region point reaches one connected part only.
  auto component = m.add_property_map<FaceIndex, std::size_t>("f:component", 0).first;
  const std::size_t shells = PMP::connected_components(m, component);
  if (shells != 1)
    throw core::GeometryError(prefix + "the surface has " + std::to_string(shells) +
                              " separate shells, expected 1. Hint: give each solid its own file "
                              "and body.");
}

SurfaceSolid solid_from_file(const std::filesystem::path& file, double scale,
                             const std::string& prefix) {
  Mesh m = triangle_mesh(triangle_soup(file, scale, prefix), prefix);
  const CGAL::Bbox_3 box = PMP::bbox(m);
  const double diagonal =
      std::sqrt(CGAL::square(box.xmax() - box.xmin()) + CGAL::square(box.ymax() - box.ymin()) +
                CGAL::square(box.zmax() - box.zmin()));
  check_one_closed_shell(m, prefix);
  // Outward, with positive volume.
  if (!PMP::is_outward_oriented(m)) PMP::reverse_face_orientations(m);
  SurfaceSolid solid;
  solid.volume = PMP::volume(m);
  if (!(solid.volume > 0)) {
    std::ostringstream msg;
    msg << prefix << "the surface encloses a volume of " << solid.volume
        << " m^3, expected > 0. Hint: check the file and its length unit.";
    throw core::GeometryError(msg.str());
  }
  solid.inside_point = inside_point_of(m, diagonal, prefix);
  solid.surface = surface_of(m);
  return solid;
}

}  // namespace

SurfaceSolid surface_solid(const std::filesystem::path& file, double scale,
                           const std::string& what) {
  const std::string prefix = file.string() + " (" + what + "): ";
  try {
    return solid_from_file(file, scale, prefix);
  } catch (const CGAL::Failure_exception& e) {
    // A precondition or assertion of CGAL's on a surface that passed every check before it.
    throw core::GeometryError(prefix + "the geometry library refused the surface (" +
                              e.expression() + " at " + e.filename() + ":" +
                              std::to_string(e.line_number()) +
                              "). Hint: check the file for degenerate or far-flung triangles.");
  }
}

std::vector<PointLocation> locate_points(const TriangleSurface& surface,
                                         const std::vector<Eigen::Vector3d>& points, double tol) {
  const Mesh m = mesh_of(surface);
  const Tree tree(faces(m).first, faces(m).second, m);
  const Inside side(m);
  std::vector<PointLocation> out(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    for (size_t v = 0; v < surface.vertices.size(); ++v)
      if ((surface.vertices[v] - p).norm() <= tol) {
        out[i] = {PointLocation::Kind::vertex, static_cast<int>(v)};
        break;
      }
    if (out[i].kind == PointLocation::Kind::vertex) continue;
    const auto [closest, face] = tree.closest_point_and_primitive(point(p));
    if ((eigen(closest) - p).norm() <= tol)
      out[i] = {PointLocation::Kind::triangle, static_cast<int>(face.idx())};
    else if (side(point(p)) == CGAL::ON_BOUNDED_SIDE)
      out[i] = {PointLocation::Kind::inside, -1};
  }
  return out;
}

bool solids_meet(const TriangleSurface& a, const TriangleSurface& b) {
  const Mesh ma = mesh_of(a), mb = mesh_of(b);
  return PMP::do_intersect(ma, mb, CGAL::parameters::do_overlap_test_of_bounded_sides(true),
                           CGAL::parameters::do_overlap_test_of_bounded_sides(true));
}

bool solid_strictly_inside(const TriangleSurface& a, const TriangleSurface& b) {
  const Mesh ma = mesh_of(a), mb = mesh_of(b);
  if (PMP::do_intersect(ma, mb)) return false;
  const Inside side(mb);
  return side(point(a.vertices.front())) == CGAL::ON_BOUNDED_SIDE;
}

}  // namespace tt::mesh::cgal
