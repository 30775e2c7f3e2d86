#include "mesh/mesher.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>
#include <unordered_map>

#include "core/errors.hpp"
#include "mesh/extrusion.hpp"
#include "mesh/tetgen/tetgen_adapter.hpp"

namespace tt::mesh {
namespace {

using Eigen::Vector3d;

/// Outward faces of a positively oriented tet, as local corner indices.
constexpr int kFaceCorners[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
/// VTK's mid-edge node order of the quadratic tetra.
constexpr int kTetEdges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};

int edge_slot(int a, int b) {
  for (int e = 0; e < 6; ++e)
    if ((kTetEdges[e][0] == a && kTetEdges[e][1] == b) ||
        (kTetEdges[e][0] == b && kTetEdges[e][1] == a))
      return 4 + e;
  return -1;
}

struct FaceGeometry {
  Vector3d centroid, normal;
  std::array<Vector3d, 3> corners;
};

FaceGeometry face_geometry(const TetMesh& m, int f) {
  FaceGeometry g;
  for (int k = 0; k < 3; ++k) g.corners[k] = m.nodes.row(m.faces(f, k)).transpose();
  g.centroid = (g.corners[0] + g.corners[1] + g.corners[2]) / 3.0;
  g.normal = (g.corners[1] - g.corners[0]).cross(g.corners[2] - g.corners[0]).normalized();
  return g;
}

bool contains(const std::vector<int>& list, int v) {
  return std::find(list.begin(), list.end(), v) != list.end();
}

bool selector_matches(const core::FaceSelector& s, const TetMesh& m, int f, const FaceGeometry& g,
                      double tol, int circle_segments) {
  using Side = core::FaceSelector::Side;
  const bool interface = m.face_other_tet[f] >= 0;
  if (s.side == Side::exterior && interface) return false;
  if (s.side == Side::interface && !interface) return false;
  const int r0 = core::index_of(m.tet_region[m.face_tet[f]]);
  const int r1 = interface ? core::index_of(m.tet_region[m.face_other_tet[f]]) : -1;
  if (!s.bodies.empty()) {
    const bool a =
        contains(s.bodies, r0) && (s.other_bodies.empty() || contains(s.other_bodies, r1));
    const bool b = interface && contains(s.bodies, r1) &&
                   (s.other_bodies.empty() || contains(s.other_bodies, r0));
    if (!a && !b) return false;
  } else if (!s.other_bodies.empty()) {
    if (!contains(s.other_bodies, r0) && !contains(s.other_bodies, r1)) return false;
  }
  if (s.plane) {
    const Vector3d n = s.plane->head<3>();
    for (const auto& c : g.corners)
      if (std::abs(n.dot(c) - (*s.plane)[3]) > tol) return false;
  }
  if (s.on_cylinder) {
    if (std::abs(g.normal.z()) > 1e-6) return false;
    const double r = s.on_cylinder->radius;
    const double rf = faceted_radius(r, circle_segments);
    const double r_in = rf * std::cos(std::numbers::pi / circle_segments);
    for (const auto& c : g.corners) {
      const double d = (c.head<2>() - s.on_cylinder->axis).norm();
      if (d < std::min(r, r_in) - tol || d > std::max(r, rf) + tol) return false;
    }
    const double dc = (g.centroid.head<2>() - s.on_cylinder->axis).norm();
    if (dc < std::min(r, r_in) - tol) return false;
  }
  if (s.within_min && (g.centroid.array() < s.within_min->array() - tol).any()) return false;
  if (s.within_max && (g.centroid.array() > s.within_max->array() + tol).any()) return false;
  return true;
}

/// Volume of a primitive [m^3]; a surface file's from its closed surface.
double primitive_volume(const core::Primitive& p, const core::Body& body) {
  using Kind = core::Primitive::Kind;
  switch (p.kind) {
    case Kind::box:
      return (p.max - p.min).prod();
    case Kind::cylinder:
      return std::numbers::pi * p.radius * p.radius * (p.z_max - p.z_min);
    case Kind::annulus:
      return std::numbers::pi * (p.radius * p.radius - p.inner_radius * p.inner_radius) *
             (p.z_max - p.z_min);
    case Kind::surface_file:
      return std::max(0.0, exact_body_volume(body));
  }
  return 0;
}

/// Perimeter and shortest edge of a facet's rings [m] (one-vertex polygons are points).
std::pair<double, double> facet_edges(const Plc& plc, const PlcFacet& f) {
  double perimeter = 0, shortest = std::numeric_limits<double>::infinity();
  for (const auto& ring : f.polygons) {
    if (ring.size() < 2) continue;
    for (size_t k = 0; k < ring.size(); ++k) {
      const double e = (plc.vertices[ring[(k + 1) % ring.size()]] - plc.vertices[ring[k]]).norm();
      perimeter += e;
      if (e > 0) shortest = std::min(shortest, e);
    }
  }
  return {perimeter, shortest};
}

/// Area of a facet [m^2]: its outer ring's, by the vector area of each ring (holes subtract
/// themselves when wound the other way, and are counted whole otherwise: an upper bound).
double facet_area(const Plc& plc, const PlcFacet& f) {
  double area = 0;
  for (const auto& ring : f.polygons) {
    if (ring.size() < 3) continue;
    Vector3d twice = Vector3d::Zero();
    for (size_t k = 0; k < ring.size(); ++k)
      twice += plc.vertices[ring[k]].cross(plc.vertices[ring[(k + 1) % ring.size()]]);
    area = std::max(area, 0.5 * twice.norm());
  }
  return area;
}

/// Each boundary triangle starts a graded layer of tets.
constexpr double kSurfaceFill = 4.0;

}  // namespace

MeshEstimate mesh_estimate(const core::CaseSpec& spec) {
  MeshEstimate e;
  // A regular tet of edge h has volume h^3 / (6 sqrt 2); TetGen's -a bound is that volume, and its
  // tets come out smaller than the bound on average (kVolumeFill, measured on the shipped cases).
  constexpr double kVolumeFill = 2.0;
  for (size_t b = 0; b < spec.bodies.size(); ++b) {
    const auto& body = spec.bodies[b];
    double volume = 0;
    for (const auto& p : body.add) volume += primitive_volume(p, body);
    const double h = body.max_edge;
    const double tets = kVolumeFill * volume / (h * h * h / (6.0 * std::sqrt(2.0)));
    e.volume_tets += tets;
    if (tets > e.finest_body_tets) e.finest_body_tets = tets, e.finest_body = static_cast<int>(b);
  }
  // Each side strip of a faceted cylinder (width w = 2 pi r / n, height h) needs about h / w
  // triangles: known from the spec alone, before the PLC (whose building grows with n too).
  const double n = spec.mesh.circle_segments;
  for (const auto& body : spec.bodies)
    for (const auto* list : {&body.add, &body.subtract})
      for (const auto& p : *list) {
        using Kind = core::Primitive::Kind;
        if (p.kind != Kind::cylinder && p.kind != Kind::annulus) continue;
        const double h = p.z_max - p.z_min;
        for (const double r : {p.radius, p.kind == Kind::annulus ? p.inner_radius : 0.0})
          if (r > 0)
            e.surface_tets += kSurfaceFill * n * std::max(1.0, h * n / (2 * std::numbers::pi * r));
      }
  return e;
}

MeshEstimate mesh_estimate(const core::CaseSpec& spec, const Plc& plc) {
  MeshEstimate e = mesh_estimate(spec);
  e.surface_tets = 0;
  // A facet needs at least as many triangles as its boundary has shortest edges along it (a long
  // thin strip: length / width), and no more than its area holds at that edge; each boundary
  // triangle starts a graded layer of tets (kSurfaceFill).
  for (const auto& f : plc.facets) {
    const auto [perimeter, shortest] = facet_edges(plc, f);
    if (!std::isfinite(shortest)) continue;
    const double triangles =
        std::max(1.0, std::min(perimeter / shortest, facet_area(plc, f) / (shortest * shortest)));
    e.surface_tets += kSurfaceFill * triangles;
  }
  return e;
}

void require_mesh_within_bounds(const core::CaseSpec& spec, const MeshEstimate& e) {
  if (e.tets() <= spec.mesh.max_tets) return;
  std::ostringstream o;
  o.precision(3);
  o << spec.source.string() << ": the mesh would have about " << e.tets()
    << " tetrahedra, more than mesh.max_tets = " << spec.mesh.max_tets << " (estimated before "
    << "meshing: " << e.volume_tets << " from the bodies' volumes at their max_edge";
  if (e.finest_body >= 0)
    o << ", most in body '" << spec.bodies[e.finest_body].name
      << "' at max_edge = " << spec.bodies[e.finest_body].max_edge << " m";
  o << "; " << e.surface_tets
    << " from the surface facets, mesh.circle_segments = " << spec.mesh.circle_segments
    << "). Hint: coarsen max_edge or circle_segments, or raise "
    << "max_tets under [mesh] when the machine has the memory (about 1 GB per 100 000 tets of "
       "order 2 in a run).";
  throw core::MeshError(o.str());
}

namespace {

/// Sorted corner nodes of local face f of tet t: the key shared by the two tets of a face.
std::array<int, 3> face_key(const TetMesh& m, int t, int f) {
  std::array<int, 3> key = {m.tets(t, kFaceCorners[f][0]), m.tets(t, kFaceCorners[f][1]),
                            m.tets(t, kFaceCorners[f][2])};
  std::sort(key.begin(), key.end());
  return key;
}

/// Node coordinates: TetGen's corners, then (order 2) one mid-edge node per edge, numbered as
/// the tets first reach them and written into the tets' columns 4..9.
std::vector<Vector3d> nodes_with_mid_edges(const LinearTets& lin, TetMesh& m) {
  std::vector<Vector3d> nodes = lin.nodes;
  if (m.order != 2) return nodes;
  const int nt = static_cast<int>(lin.tets.size());
  const int nc = static_cast<int>(lin.nodes.size());
  std::unordered_map<long long, int> mid;
  mid.reserve(static_cast<size_t>(nt) * 2);
  for (int t = 0; t < nt; ++t) {
    for (int e = 0; e < 6; ++e) {
      const int a = m.tets(t, kTetEdges[e][0]), b = m.tets(t, kTetEdges[e][1]);
      const long long key = static_cast<long long>(std::min(a, b)) * nc + std::max(a, b);
      auto [it, fresh] = mid.emplace(key, static_cast<int>(nodes.size()));
      if (fresh) nodes.push_back(0.5 * (nodes[a] + nodes[b]));
      m.tets(t, 4 + e) = it->second;
    }
  }
  return nodes;
}

/// The faces to keep as (tet, local face, other tet), sorted: faces seen once are exterior
/// (other -1); faces between different bodies are interfaces, owned by the lower body index.
std::vector<std::array<int, 3>> boundary_faces(const TetMesh& m) {
  struct Seen {
    int tet, local, count, other;
  };
  std::map<std::array<int, 3>, Seen> seen;
  for (int t = 0; t < static_cast<int>(m.tets.rows()); ++t) {
    for (int f = 0; f < 4; ++f) {
      auto [it, fresh] = seen.emplace(face_key(m, t, f), Seen{t, f, 1, -1});
      if (!fresh) {
        ++it->second.count;
        it->second.other = t;
      }
    }
  }
  std::vector<std::array<int, 3>> picked;
  for (const auto& [key, s] : seen) {
    if (s.count == 1)
      picked.push_back({s.tet, s.local, -1});
    else if (m.tet_region[s.tet] != m.tet_region[s.other]) {
      const bool swap = core::index_of(m.tet_region[s.other]) < core::index_of(m.tet_region[s.tet]);
      int owner = swap ? s.other : s.tet, other = swap ? s.tet : s.other;
      int local = s.local;
      if (swap) {
        for (int f = 0; f < 4; ++f)
          if (face_key(m, owner, f) == key) local = f;
      }
      picked.push_back({owner, local, other});
    }
  }
  std::sort(picked.begin(), picked.end());
  return picked;
}

/// m.faces, face_tet and face_other_tet from the picked (tet, local face, other tet).
void set_faces(const std::vector<std::array<int, 3>>& picked, TetMesh& m) {
  const int npf = m.order == 1 ? 3 : 6;
  m.faces.resize(static_cast<int>(picked.size()), npf);
  m.face_tet.resize(picked.size());
  m.face_other_tet.resize(picked.size());
  for (size_t i = 0; i < picked.size(); ++i) {
    const auto [t, f, other] = picked[i];
    const int* c = kFaceCorners[f];
    for (int k = 0; k < 3; ++k) m.faces(static_cast<int>(i), k) = m.tets(t, c[k]);
    if (m.order == 2) {
      m.faces(static_cast<int>(i), 3) = m.tets(t, edge_slot(c[0], c[1]));
      m.faces(static_cast<int>(i), 4) = m.tets(t, edge_slot(c[1], c[2]));
      m.faces(static_cast<int>(i), 5) = m.tets(t, edge_slot(c[2], c[0]));
    }
    m.face_tet[i] = t;
    m.face_other_tet[i] = other;
  }
}

/// Each face's boundary group: ordinary groups in order first, then the "rest" groups in order;
/// a face takes the first group that selects it.
void set_face_groups(const core::CaseSpec& spec, TetMesh& m) {
  for (const auto& grp : spec.groups) m.group_names.push_back(grp.name);
  const int nf = static_cast<int>(m.faces.rows());
  m.face_group.assign(nf, core::BoundaryId{-1});
  const double tol = selection_tolerance(m.nodes);
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t gi = 0; gi < spec.groups.size(); ++gi) {
      if (spec.groups[gi].rest != (pass == 1)) continue;
      for (int f = 0; f < nf; ++f) {
        if (core::index_of(m.face_group[f]) >= 0) continue;
        const FaceGeometry g = face_geometry(m, f);
        for (const auto& s : spec.groups[gi].select) {
          if (selector_matches(s, m, f, g, tol, spec.mesh.circle_segments)) {
            m.face_group[f] = core::BoundaryId{static_cast<int>(gi)};
            break;
          }
        }
      }
    }
  }
}

/// The named points at their PLC vertices (or the nearest corner node when TetGen inserted
/// them); a point that names a boundary group must lie on one of its faces.
void set_named_points(const LinearTets& lin, const core::CaseSpec& spec,
                      const std::vector<int>& point_vertex, TetMesh& m) {
  const int nc = static_cast<int>(lin.nodes.size());
  for (size_t i = 0; i < spec.points.size(); ++i) {
    const auto& p = spec.points[i];
    int node = point_vertex[i];
    if (node < 0) {
      double best = 1e300;
      for (int v = 0; v < nc; ++v) {
        const double d = (lin.nodes[v] - p.position).norm();
        if (d < best) best = d, node = v;
      }
    }
    m.points.push_back(NamedNode{p.id, p.position, node});
    if (p.on_group >= 0) {
      bool on = false;
      for (int f = 0; f < m.faces.rows() && !on; ++f)
        if (core::index_of(m.face_group[f]) == p.on_group)
          for (int k = 0; k < 3; ++k) on = on || m.faces(f, k) == node;
      if (!on)
        throw core::GeometryError(spec.source.string() + ": points.list '" + p.id +
                                  "' is not on boundary group '" + spec.groups[p.on_group].name +
                                  "' that it names. Hint: check its coordinates.");
    }
  }
}

}  // namespace

TetMesh assemble_mesh(const LinearTets& lin, const core::CaseSpec& spec,
                      const std::vector<int>& point_vertex) {
  TetMesh m;
  m.order = spec.mesh.order;
  const int nt = static_cast<int>(lin.tets.size());
  m.corner_count = static_cast<int>(lin.nodes.size());
  for (const auto& b : spec.bodies) m.region_names.push_back(b.name);
  m.tets.resize(nt, m.order == 1 ? 4 : 10);
  m.tet_region.resize(nt);
  for (int t = 0; t < nt; ++t) {
    for (int k = 0; k < 4; ++k) m.tets(t, k) = lin.tets[t][k];
    m.tet_region[t] = core::RegionId{lin.region[t]};
  }
  const std::vector<Vector3d> nodes = nodes_with_mid_edges(lin, m);
  m.nodes.resize(static_cast<int>(nodes.size()), 3);
  for (size_t i = 0; i < nodes.size(); ++i) m.nodes.row(static_cast<int>(i)) = nodes[i].transpose();
  set_faces(boundary_faces(m), m);
  set_face_groups(spec, m);
  set_named_points(lin, spec, point_vertex, m);
  return m;
}

TetMesh mesh_case(const core::CaseSpec& spec) {
  require_mesh_within_bounds(spec, mesh_estimate(spec));
  const ExtrudedPlc plc = extruded_plc(spec);
  require_mesh_within_bounds(spec, mesh_estimate(spec, plc.plc));
  TetgenOptions options;
  options.radius_edge_ratio = spec.mesh.radius_edge_ratio;
  options.min_dihedral_deg = spec.mesh.min_dihedral_deg;
  options.time_limit_s = spec.mesh.time_limit_s;
  options.memory_limit_GB = spec.mesh.memory_limit_GB;
  const LinearTets lin = tetgen::tetrahedralize(plc.plc, options);
  std::vector<int> vertex = plc.point_vertex;
  // Points inserted inside were appended after the PLC's vertices; find them exactly.
  for (size_t i = 0; i < vertex.size(); ++i) {
    if (vertex[i] >= 0) continue;
    for (size_t v = 0; v < lin.nodes.size(); ++v)
      if (lin.nodes[v] == spec.points[i].position) vertex[i] = static_cast<int>(v);
    if (vertex[i] < 0)
      throw core::MeshError(spec.source.string() + ": TetGen did not keep point '" +
                            spec.points[i].id + "' as a vertex");
  }
  return assemble_mesh(lin, spec, vertex);
}

std::vector<double> tet_volumes(const TetMesh& m) {
  std::vector<double> v(m.tets.rows());
  for (int t = 0; t < m.tets.rows(); ++t) {
    const Vector3d a = m.nodes.row(m.tets(t, 0)).transpose();
    v[t] = (m.nodes.row(m.tets(t, 1)).transpose() - a)
               .cross(m.nodes.row(m.tets(t, 2)).transpose() - a)
               .dot(m.nodes.row(m.tets(t, 3)).transpose() - a) /
           6.0;
  }
  return v;
}

std::vector<double> face_areas(const TetMesh& m) {
  std::vector<double> a(m.faces.rows());
  for (int f = 0; f < m.faces.rows(); ++f) {
    const Vector3d p = m.nodes.row(m.faces(f, 0)).transpose();
    a[f] = 0.5 * (m.nodes.row(m.faces(f, 1)).transpose() - p)
                     .cross(m.nodes.row(m.faces(f, 2)).transpose() - p)
                     .norm();
  }
  return a;
}

double min_dihedral_deg(const TetMesh& m) {
  double worst = 180;
  for (int t = 0; t < m.tets.rows(); ++t) {
    Vector3d x[4];
    for (int k = 0; k < 4; ++k) x[k] = m.nodes.row(m.tets(t, k)).transpose();
    Vector3d n[4];
    for (int f = 0; f < 4; ++f) {
      const int* c = kFaceCorners[f];
      n[f] = (x[c[1]] - x[c[0]]).cross(x[c[2]] - x[c[0]]).normalized();
    }
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const double cosine = std::clamp(-n[i].dot(n[j]), -1.0, 1.0);
        worst = std::min(worst, std::acos(cosine) * 180.0 / std::numbers::pi);
      }
  }
  return worst;
}

MeshReport mesh_report(const TetMesh& m, const core::CaseSpec& spec) {
  MeshReport r;
  r.nodes = static_cast<int>(m.nodes.rows());
  r.tets = static_cast<int>(m.tets.rows());
  r.order = m.order;
  r.min_dihedral_deg = min_dihedral_deg(m);
  const auto vol = tet_volumes(m);
  for (size_t b = 0; b < spec.bodies.size(); ++b) {
    BodyReport br{spec.bodies[b].name, 0, exact_body_volume(spec.bodies[b])};
    for (int t = 0; t < m.tets.rows(); ++t)
      if (core::index_of(m.tet_region[t]) == static_cast<int>(b)) br.volume += vol[t];
    r.bodies.push_back(br);
  }
  const auto area = face_areas(m);
  r.group_areas.assign(m.group_names.size(), 0.0);
  for (int f = 0; f < m.faces.rows(); ++f)
    if (core::index_of(m.face_group[f]) >= 0)
      r.group_areas[core::index_of(m.face_group[f])] += area[f];
  for (const auto& p : m.points)
    r.point_distance.push_back((m.nodes.row(p.node).transpose() - p.position).norm());
  return r;
}

double selection_tolerance(const NodeMatrix& nodes) {
  if (nodes.rows() == 0) return 0;
  return 1e-7 * (nodes.colwise().maxCoeff() - nodes.colwise().minCoeff()).norm();
}

}  // namespace tt::mesh
