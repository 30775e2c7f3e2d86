#include "mesh/extrusion.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <numeric>
#include <optional>
#include <sstream>

#include "core/errors.hpp"
#include "mesh/cgal/surface_body.hpp"

namespace tt::mesh {
namespace {

using core::Body;
using core::Primitive;
using Eigen::Vector2d;
using Eigen::Vector3d;

/// A closed ring of 2D points, counter-clockwise.
using Ring = std::vector<Vector2d>;

double cross2(const Vector2d& a, const Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

double signed_area(const Ring& ring) {
  double a = 0;
  for (size_t i = 0; i < ring.size(); ++i) a += cross2(ring[i], ring[(i + 1) % ring.size()]);
  return 0.5 * a;
}

/// Crossing-number test; points on the boundary may go either way (callers avoid them).
bool ring_contains(const Ring& ring, const Vector2d& p) {
  bool inside = false;
  for (size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Vector2d& a = ring[i];
    const Vector2d& b = ring[j];
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (p.x() < x) inside = !inside;
    }
  }
  return inside;
}

double segment_distance(const Vector2d& p, const Vector2d& a, const Vector2d& b) {
  const Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  double t = len2 > 0 ? (p - a).dot(ab) / len2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  return (a + t * ab - p).norm();
}

/// Cross-section rings of a primitive: (outer, inner or empty).
std::pair<Ring, Ring> primitive_rings(const Primitive& p, int n) {
  switch (p.kind) {
    case Primitive::Kind::box:
      return {Ring{{p.min.x(), p.min.y()},
                   {p.max.x(), p.min.y()},
                   {p.max.x(), p.max.y()},
                   {p.min.x(), p.max.y()}},
              {}};
    case Primitive::Kind::cylinder:
      return {faceted_circle(p.axis, p.radius, n), {}};
    case Primitive::Kind::annulus:
      return {faceted_circle(p.axis, p.radius, n), faceted_circle(p.axis, p.inner_radius, n)};
    case Primitive::Kind::surface_file:
      break;
  }
  throw core::GeometryError(p.where +
                            ": surface-file primitives cannot be combined with "
                            "z-extruded primitives in one body");
}

std::pair<double, double> z_range(const Primitive& p) {
  if (p.kind == Primitive::Kind::box) return {p.min.z(), p.max.z()};
  return {p.z_min, p.z_max};
}

/// Membership with a small tolerance band counted as inside.
bool convex_or_rect_contains(const Ring& ring, const Vector2d& q, double tol) {
  if (ring_contains(ring, q)) return true;
  for (size_t i = 0; i < ring.size(); ++i)
    if (segment_distance(q, ring[i], ring[(i + 1) % ring.size()]) <= tol) return true;
  return false;
}

bool primitive_contains(const Primitive& p, const Vector3d& x, int n, double tol) {
  const auto [z0, z1] = z_range(p);
  if (x.z() < z0 - tol || x.z() > z1 + tol) return false;
  const auto [outer, inner] = primitive_rings(p, n);
  const Vector2d q(x.x(), x.y());
  if (!convex_or_rect_contains(outer, q, tol)) return false;
  if (!inner.empty() && ring_contains(inner, q)) {
    bool on_inner = false;
    for (size_t i = 0; i < inner.size(); ++i)
      if (segment_distance(q, inner[i], inner[(i + 1) % inner.size()]) <= tol) on_inner = true;
    return on_inner;
  }
  return true;
}

bool body_contains_tol(const Body& body, const Vector3d& x, int n, double tol, double sub_tol) {
  bool in = false;
  for (const auto& p : body.add)
    if (primitive_contains(p, x, n, tol)) in = true;
  if (!in) return false;
  for (const auto& p : body.subtract)
    if (primitive_contains(p, x, n, sub_tol)) return false;
  return true;
}

// ---------------------------------------------------------------------------------------------
// The planar straight-line graph of all cross-section boundaries and its faces.

struct Pslg {
  std::vector<Vector2d> vertices;
  std::vector<std::array<int, 2>> edges;
  double tol = 0;

  int vertex(const Vector2d& p) {
    for (size_t i = 0; i < vertices.size(); ++i)
      if ((vertices[i] - p).norm() <= tol) return static_cast<int>(i);
    vertices.push_back(p);
    return static_cast<int>(vertices.size()) - 1;
  }
};

/// Inserts proper crossings, splits edges at vertices on them, removes duplicate edges.
void resolve_pslg(Pslg& g) {
  const double tol = g.tol;
  // Proper crossings between edges.
  const size_t ne = g.edges.size();
  for (size_t i = 0; i < ne; ++i) {
    for (size_t j = i + 1; j < ne; ++j) {
      const Vector2d a = g.vertices[g.edges[i][0]], b = g.vertices[g.edges[i][1]];
      const Vector2d c = g.vertices[g.edges[j][0]], d = g.vertices[g.edges[j][1]];
      const double denom = cross2(b - a, d - c);
      if (std::abs(denom) <= 1e-14 * (b - a).norm() * (d - c).norm()) continue;  // parallel
      const double t = cross2(c - a, d - c) / denom;
      const double u = cross2(c - a, b - a) / denom;
      const double ta = tol / (b - a).norm(), tc = tol / (d - c).norm();
      if (t > ta && t < 1 - ta && u > tc && u < 1 - tc) g.vertex(a + t * (b - a));
    }
  }
  // Split every edge at the vertices lying on it.
  std::vector<std::array<int, 2>> split;
  for (const auto& e : g.edges) {
    const Vector2d a = g.vertices[e[0]], b = g.vertices[e[1]];
    const double len = (b - a).norm();
    std::vector<std::pair<double, int>> on;
    for (size_t v = 0; v < g.vertices.size(); ++v) {
      if (static_cast<int>(v) == e[0] || static_cast<int>(v) == e[1]) continue;
      const Vector2d& p = g.vertices[v];
      const double t = (p - a).dot(b - a) / (len * len);
      if (t * len <= tol || (1 - t) * len <= tol) continue;
      if (segment_distance(p, a, b) <= tol) on.push_back({t, static_cast<int>(v)});
    }
    std::sort(on.begin(), on.end());
    int prev = e[0];
    for (const auto& [t, v] : on) {
      split.push_back({prev, v});
      prev = v;
    }
    split.push_back({prev, e[1]});
  }
  std::map<std::pair<int, int>, int> seen;
  g.edges.clear();
  for (const auto& e : split) {
    if (e[0] == e[1]) continue;
    const auto key = std::minmax(e[0], e[1]);
    if (seen.emplace(key, 1).second) g.edges.push_back({key.first, key.second});
  }
}

struct Face {
  std::vector<int> outer;               /// vertex ring, counter-clockwise
  std::vector<std::vector<int>> holes;  /// vertex rings, clockwise
};

struct Arrangement {
  std::vector<Face> faces;
  std::vector<int>
      halfedge_face;  /// per half-edge 2e (a->b) and 2e+1 (b->a): face on its left, -1 unbounded
};

Ring ring_of(const Pslg& g, const std::vector<int>& ids) {
  Ring r;
  for (int i : ids) r.push_back(g.vertices[i]);
  return r;
}

/// The half-edges of a graph, 2e (a->b) and 2e+1 (b->a), with those leaving each vertex sorted
/// by angle, so that `next` walks the boundary of the face on a half-edge's left.
struct HalfEdges {
  const Pslg* g = nullptr;
  std::vector<std::vector<int>> out;  /// per vertex: its outgoing half-edges by angle
  std::vector<int> pos;               /// per half-edge: its index in out[origin]

  int count() const { return 2 * static_cast<int>(g->edges.size()); }
  int origin(int h) const { return g->edges[h / 2][h % 2]; }
  int dest(int h) const { return g->edges[h / 2][1 - h % 2]; }
  int next(int h) const {
    const int v = dest(h);
    const int twin = h ^ 1;
    const int deg = static_cast<int>(out[v].size());
    return out[v][(pos[twin] - 1 + deg) % deg];
  }
};

HalfEdges half_edges(const Pslg& g) {
  HalfEdges he{&g, {}, {}};
  const int nv = static_cast<int>(g.vertices.size());
  he.out.resize(nv);
  for (int h = 0; h < he.count(); ++h) he.out[he.origin(h)].push_back(h);
  for (int v = 0; v < nv; ++v) {
    auto angle = [&](int h) {
      const Vector2d d = g.vertices[he.dest(h)] - g.vertices[v];
      return std::atan2(d.y(), d.x());
    };
    std::sort(he.out[v].begin(), he.out[v].end(),
              [&](int a, int b) { return angle(a) < angle(b); });
  }
  he.pos.resize(he.count());
  for (int v = 0; v < nv; ++v)
    for (size_t k = 0; k < he.out[v].size(); ++k) he.pos[he.out[v][k]] = static_cast<int>(k);
  return he;
}

/// Per vertex, a representative of its connected component: a hole's container must belong to
/// another component than the hole's own outer cycle.
std::vector<int> components(const Pslg& g) {
  std::vector<int> comp(g.vertices.size());
  std::iota(comp.begin(), comp.end(), 0);
  std::function<int(int)> find = [&](int x) { return comp[x] == x ? x : comp[x] = find(comp[x]); };
  for (const auto& e : g.edges) comp[find(e[0])] = find(e[1]);
  std::vector<int> root(comp.size());
  for (size_t v = 0; v < comp.size(); ++v) root[v] = find(static_cast<int>(v));
  return root;
}

/// A closed walk of half-edges: the outer boundary of a face (area > 0) or a hole (area <= 0).
struct Cycle {
  std::vector<int> ring;  /// vertices
  double area;
  int component;
};

/// Every half-edge's cycle; `of_halfedge` maps a half-edge to its index in `list`.
struct Cycles {
  std::vector<Cycle> list;
  std::vector<int> of_halfedge;
};

Cycles boundary_cycles(const Pslg& g, const HalfEdges& he) {
  const std::vector<int> component = components(g);
  Cycles cycles{{}, std::vector<int>(he.count(), -1)};
  for (int h0 = 0; h0 < he.count(); ++h0) {
    if (cycles.of_halfedge[h0] >= 0) continue;
    Cycle c;
    int h = h0;
    do {
      cycles.of_halfedge[h] = static_cast<int>(cycles.list.size());
      c.ring.push_back(he.origin(h));
      h = he.next(h);
    } while (h != h0);
    c.area = signed_area(ring_of(g, c.ring));
    c.component = component[c.ring[0]];
    cycles.list.push_back(std::move(c));
  }
  return cycles;
}

/// The smallest outer cycle of another component that contains hole cycle `c`; -1 when none
/// does (the hole bounds the unbounded face).
int enclosing_cycle(const Pslg& g, const std::vector<Cycle>& cycles, size_t c) {
  const Vector2d p = g.vertices[cycles[c].ring[0]];
  int best = -1;
  double best_area = 0;
  for (size_t d = 0; d < cycles.size(); ++d) {
    if (cycles[d].area <= 0 || cycles[d].component == cycles[c].component) continue;
    if (!ring_contains(ring_of(g, cycles[d].ring), p)) continue;
    if (best < 0 || cycles[d].area < best_area) {
      best = static_cast<int>(d);
      best_area = cycles[d].area;
    }
  }
  return best;
}

Arrangement arrangement(const Pslg& g) {
  const HalfEdges he = half_edges(g);
  const Cycles cycles = boundary_cycles(g, he);
  const std::vector<Cycle>& list = cycles.list;
  Arrangement arr;
  std::vector<int> face_of_cycle(list.size(), -1);
  for (size_t c = 0; c < list.size(); ++c) {
    if (list[c].area > 0) {
      face_of_cycle[c] = static_cast<int>(arr.faces.size());
      arr.faces.push_back(Face{list[c].ring, {}});
    }
  }
  for (size_t c = 0; c < list.size(); ++c) {
    if (list[c].area > 0) continue;
    const int best = enclosing_cycle(g, list, c);
    if (best >= 0) {
      face_of_cycle[c] = face_of_cycle[best];
      arr.faces[face_of_cycle[best]].holes.push_back(list[c].ring);
    }
  }
  arr.halfedge_face.assign(he.count(), -1);
  for (int h = 0; h < he.count(); ++h) arr.halfedge_face[h] = face_of_cycle[cycles.of_halfedge[h]];
  return arr;
}

bool face_contains(const Pslg& g, const Face& f, const Vector2d& p) {
  if (!ring_contains(ring_of(g, f.outer), p)) return false;
  for (const auto& h : f.holes)
    if (ring_contains(ring_of(g, h), p)) return false;
  return true;
}

/// A point strictly inside the region left (side = +1) or right (side = -1) of a ring's edges,
/// clear of every edge of the graph.
Vector2d point_beside(const Pslg& g, const std::vector<int>& ring, int side,
                      const std::function<bool(const Vector2d&)>& accept) {
  for (size_t i = 0; i < ring.size(); ++i) {
    const Vector2d a = g.vertices[ring[i]], b = g.vertices[ring[(i + 1) % ring.size()]];
    const Vector2d m = 0.5 * (a + b);
    const Vector2d t = (b - a).normalized();
    const Vector2d left(-t.y(), t.x());
    double clearance = 0.5 * (b - a).norm();
    for (const auto& e : g.edges) {
      const Vector2d c = g.vertices[e[0]], d = g.vertices[e[1]];
      if ((e[0] == ring[i] && e[1] == ring[(i + 1) % ring.size()]) ||
          (e[1] == ring[i] && e[0] == ring[(i + 1) % ring.size()]))
        continue;
      clearance = std::min(clearance, segment_distance(m, c, d));
    }
    const Vector2d p = m + side * 0.5 * clearance * left;
    if (clearance > 2 * g.tol && accept(p)) return p;
  }
  throw core::GeometryError(
      "could not find an interior point of a cross-section face; the "
      "geometry has features below the tolerance " +
      std::to_string(g.tol) + " m");
}

struct ZValue {
  double z;
  bool from_point;
};

std::vector<double> merged_breakpoints(std::vector<ZValue> values, double tol) {
  std::sort(values.begin(), values.end(), [](auto& a, auto& b) { return a.z < b.z; });
  std::vector<double> out;
  for (size_t i = 0; i < values.size();) {
    size_t j = i;
    double chosen = values[i].z;
    bool have_point = values[i].from_point;
    while (j + 1 < values.size() && values[j + 1].z - values[i].z <= tol) {
      ++j;
      if (values[j].from_point && !have_point) {
        chosen = values[j].z;
        have_point = true;
      }
    }
    out.push_back(chosen);
    i = j + 1;
  }
  return out;
}

core::GeometryError outside_every_body(const core::CaseSpec& spec, const core::NamedPoint& pt) {
  std::ostringstream msg;
  msg << spec.source.string() << ": points.list '" << pt.id << "' at (" << pt.position.x() << ", "
      << pt.position.y() << ", " << pt.position.z()
      << ") m is outside every body. Hint: check its coordinates and the length unit.";
  return core::GeometryError(msg.str());
}

/// Axis-aligned bounds of a z-extruded primitive, circles taken at their nominal radius.
Eigen::AlignedBox3d primitive_bounds(const Primitive& p) {
  if (p.kind == Primitive::Kind::box) return Eigen::AlignedBox3d(p.min, p.max);
  const double r = p.radius;
  return Eigen::AlignedBox3d(Vector3d(p.axis.x() - r, p.axis.y() - r, p.z_min),
                             Vector3d(p.axis.x() + r, p.axis.y() + r, p.z_max));
}

/// The closed, outward-oriented surface of a box or of a faceted cylinder or annulus: the same
/// facets the extrusion meshes, for testing surface-file bodies against it.
cgal::TriangleSurface primitive_surface(const Primitive& p, int n) {
  const auto [outer, inner] = primitive_rings(p, n);
  const auto [z0, z1] = z_range(p);
  cgal::TriangleSurface s;
  auto ring_at = [&](const Ring& ring, double z) {
    const int first = static_cast<int>(s.vertices.size());
    for (const auto& q : ring) s.vertices.emplace_back(q.x(), q.y(), z);
    return first;
  };
  auto walls = [&](int bottom, int top, int count, bool outward) {
    for (int a = 0; a < count; ++a) {
      const int b = (a + 1) % count;
      if (outward) {
        s.triangles.push_back({bottom + a, bottom + b, top + b});
        s.triangles.push_back({bottom + a, top + b, top + a});
      } else {
        s.triangles.push_back({bottom + a, top + b, bottom + b});
        s.triangles.push_back({bottom + a, top + a, top + b});
      }
    }
  };
  const int m = static_cast<int>(outer.size());
  const int o0 = ring_at(outer, z0), o1 = ring_at(outer, z1);
  walls(o0, o1, m, true);
  if (inner.empty()) {
    Vector2d c = Vector2d::Zero();
    for (const auto& q : outer) c += q / m;
    const int c0 = static_cast<int>(s.vertices.size());
    s.vertices.emplace_back(c.x(), c.y(), z0);
    s.vertices.emplace_back(c.x(), c.y(), z1);
    for (int a = 0; a < m; ++a) {
      const int b = (a + 1) % m;
      s.triangles.push_back({c0, o0 + b, o0 + a});
      s.triangles.push_back({c0 + 1, o1 + a, o1 + b});
    }
  } else {
    // Inner and outer rings of an annulus share their angles, so each cap is a ring of quads.
    const int i0 = ring_at(inner, z0), i1 = ring_at(inner, z1);
    walls(i0, i1, m, false);
    for (int a = 0; a < m; ++a) {
      const int b = (a + 1) % m;
      s.triangles.push_back({o1 + a, o1 + b, i1 + b});
      s.triangles.push_back({o1 + a, i1 + b, i1 + a});
      s.triangles.push_back({o0 + a, i0 + b, o0 + b});
      s.triangles.push_back({o0 + a, i0 + a, i0 + b});
    }
  }
  return s;
}

}  // namespace

double faceted_radius(double r, int n) {
  const double a = 2 * std::numbers::pi / n;
  return r * std::sqrt(a / std::sin(a));
}

std::vector<Vector2d> faceted_circle(const Vector2d& centre, double r, int n) {
  const double rf = faceted_radius(r, n);
  std::vector<Vector2d> ring(n);
  for (int k = 0; k < n; ++k) {
    const double a = 2 * std::numbers::pi * k / n;
    ring[k] = centre + rf * Vector2d(std::cos(a), std::sin(a));
  }
  return ring;
}

bool body_contains(const Body& body, const Vector3d& p, int circle_segments) {
  // On the body's surface counts as inside; so does the surface of a void it subtracts: only a
  // point strictly inside the void (by more than 1 nm) is outside the body.
  return body_contains_tol(body, p, circle_segments, 1e-9, -1e-9);
}

double exact_body_volume(const Body& body) {
  if (body.add.size() == 1 && body.subtract.empty() &&
      body.add[0].kind == Primitive::Kind::surface_file)
    return cgal::surface_solid(body.add[0].file, body.add[0].file_scale, "body '" + body.name + "'")
        .volume;
  auto volume = [](const Primitive& p) {
    switch (p.kind) {
      case Primitive::Kind::box:
        return (p.max - p.min).prod();
      case Primitive::Kind::cylinder:
        return std::numbers::pi * p.radius * p.radius * (p.z_max - p.z_min);
      case Primitive::Kind::annulus:
        return std::numbers::pi * (p.radius * p.radius - p.inner_radius * p.inner_radius) *
               (p.z_max - p.z_min);
      default:
        return -1.0;
    }
  };

  if (body.add.size() != 1) return -1;
  double v = volume(body.add[0]);
  if (v < 0) return -1;
  const auto outer = primitive_bounds(body.add[0]);
  for (size_t i = 0; i < body.subtract.size(); ++i) {
    const auto& s = body.subtract[i];
    if (body.add[0].kind != Primitive::Kind::box || s.kind == Primitive::Kind::surface_file)
      return -1;
    if (!outer.contains(primitive_bounds(s))) return -1;
    for (size_t j = 0; j < i; ++j)
      if (!primitive_bounds(s).intersection(primitive_bounds(body.subtract[j])).isEmpty())
        return -1;
    v -= volume(s);
  }
  return v;
}

namespace {

/// 1e-9 of the diagonal of every primitive's faceted bounds [m]; refuses a case without bodies.
double extrusion_tolerance(const core::CaseSpec& spec) {
  const int n = spec.mesh.circle_segments;
  Eigen::AlignedBox3d extent;
  for (const auto& b : spec.bodies)
    for (const auto* list : {&b.add, &b.subtract})
      for (const auto& p : *list) {
        const auto [outer, inner] = primitive_rings(p, n);
        const auto [z0, z1] = z_range(p);
        for (const auto& q : outer) {
          extent.extend(Vector3d(q.x(), q.y(), z0));
          extent.extend(Vector3d(q.x(), q.y(), z1));
        }
      }
  if (extent.isEmpty())
    throw core::GeometryError(spec.source.string() + ": the case has no bodies");
  return 1e-9 * extent.diagonal().norm();
}

/// The layered cells of an extrusion: the cross-section graph and its faces, the z breakpoints,
/// and per (face, slab) cell a representative point and the body that fills it (-1: empty).
struct Layers {
  Pslg g;
  Arrangement arr;
  std::vector<int> degree;          /// per 2D vertex: its number of edges
  std::vector<int> point_vertex2d;  /// per named point: its 2D vertex
  std::vector<double> z;            /// breakpoints, ascending
  int nslab = 0;
  std::vector<Vector2d> rep;            /// per face: a point inside it
  std::vector<std::vector<int>> label;  /// per face and slab: body index or -1

  int cell(int f, int j) const { return f < 0 || j < 0 || j >= nslab ? -1 : label[f][j]; }
};

/// The planar graph of every primitive's rings: named points first so that their coordinates
/// are kept exactly.
void add_cross_section(const core::CaseSpec& spec, double tol, Layers& l) {
  const int n = spec.mesh.circle_segments;
  Pslg& g = l.g;
  g.tol = tol;
  for (const auto& p : spec.points) l.point_vertex2d.push_back(g.vertex(p.position.head<2>()));
  for (const auto& b : spec.bodies)
    for (const auto* list : {&b.add, &b.subtract})
      for (const auto& p : *list) {
        const auto [outer, inner] = primitive_rings(p, n);
        for (const Ring* r : {&outer, &inner}) {
          std::vector<int> ids;
          for (const auto& q : *r) ids.push_back(g.vertex(q));
          for (size_t i = 0; i < ids.size(); ++i)
            g.edges.push_back({ids[i], ids[(i + 1) % ids.size()]});
        }
      }
  resolve_pslg(g);
  l.arr = arrangement(g);
  l.degree.assign(g.vertices.size(), 0);
  for (const auto& e : g.edges) ++l.degree[e[0]], ++l.degree[e[1]];
}

/// Breakpoints along z: primitive ends and the heights of named points on vertical faces.
void add_breakpoints(const core::CaseSpec& spec, double tol, Layers& l) {
  std::vector<ZValue> zs;
  for (const auto& b : spec.bodies)
    for (const auto* list : {&b.add, &b.subtract})
      for (const auto& p : *list) {
        const auto [z0, z1] = z_range(p);
        zs.push_back({z0, false});
        zs.push_back({z1, false});
      }
  for (size_t i = 0; i < spec.points.size(); ++i)
    if (l.degree[l.point_vertex2d[i]] > 0) zs.push_back({spec.points[i].position.z(), true});
  l.z = merged_breakpoints(zs, tol);
  l.nslab = static_cast<int>(l.z.size()) - 1;
}

/// Representative points and the body of every (face, slab) cell; two bodies in one cell overlap.
void add_cell_bodies(const core::CaseSpec& spec, Layers& l) {
  const int n = spec.mesh.circle_segments;
  const int nf = static_cast<int>(l.arr.faces.size());
  l.rep.resize(nf);
  for (int f = 0; f < nf; ++f)
    l.rep[f] = point_beside(l.g, l.arr.faces[f].outer, +1, [&](const Vector2d& p) {
      return face_contains(l.g, l.arr.faces[f], p);
    });
  l.label.assign(nf, std::vector<int>(l.nslab, -1));
  for (int f = 0; f < nf; ++f) {
    for (int j = 0; j < l.nslab; ++j) {
      const Vector3d p(l.rep[f].x(), l.rep[f].y(), 0.5 * (l.z[j] + l.z[j + 1]));
      for (size_t b = 0; b < spec.bodies.size(); ++b) {
        if (!body_contains_tol(spec.bodies[b], p, n, 0.0, 0.0)) continue;
        if (l.label[f][j] >= 0) {
          std::ostringstream msg;
          msg << spec.source.string() << ": bodies '" << spec.bodies[l.label[f][j]].name
              << "' and '" << spec.bodies[b].name << "' overlap near (" << p.x() << ", " << p.y()
              << ", " << p.z()
              << ") m without a declared subtraction. Hint: subtract one from the other, "
              << "or make them only touch.";
          throw core::GeometryError(msg.str());
        }
        l.label[f][j] = static_cast<int>(b);
      }
    }
  }
}

/// The PLC's 3D vertices, one per (2D vertex, z breakpoint), numbered as first asked for.
class LayerVertices {
 public:
  int at(const Layers& l, Plc& plc, int v2, int zi) {
    auto [it, fresh] =
        index_.emplace(std::make_pair(v2, zi), static_cast<int>(plc.vertices.size()));
    if (fresh) plc.vertices.emplace_back(l.g.vertices[v2].x(), l.g.vertices[v2].y(), l.z[zi]);
    return it->second;
  }
  /// The vertex at (v2, zi) if it exists, else -1.
  int find(int v2, int zi) const {
    const auto it = index_.find({v2, zi});
    return it == index_.end() ? -1 : it->second;
  }

 private:
  std::map<std::pair<int, int>, int> index_;
};

/// A vertical facet per graph edge and slab where the cells on its two sides differ.
void add_side_facets(const Layers& l, LayerVertices& v3, Plc& plc) {
  for (size_t e = 0; e < l.g.edges.size(); ++e) {
    const int fl = l.arr.halfedge_face[2 * e], fr = l.arr.halfedge_face[2 * e + 1];
    for (int j = 0; j < l.nslab; ++j) {
      if (l.cell(fl, j) == l.cell(fr, j)) continue;
      const int a = l.g.edges[e][0], b = l.g.edges[e][1];
      plc.facets.push_back(PlcFacet{{{v3.at(l, plc, a, j), v3.at(l, plc, b, j),
                                      v3.at(l, plc, b, j + 1), v3.at(l, plc, a, j + 1)}},
                                    {}});
    }
  }
}

/// A horizontal facet per face and breakpoint where the cells below and above differ, with its
/// holes and the named points floating inside it (their vertices go to result.point_vertex).
void add_cap_facets(const core::CaseSpec& spec, const Layers& l, double tol, LayerVertices& v3,
                    ExtrudedPlc& result) {
  Plc& plc = result.plc;
  const int nf = static_cast<int>(l.arr.faces.size());
  std::vector<int> isolated_face(spec.points.size(), -1);
  for (size_t i = 0; i < spec.points.size(); ++i)
    if (l.degree[l.point_vertex2d[i]] == 0)
      for (int f = 0; f < nf; ++f)
        if (face_contains(l.g, l.arr.faces[f], l.g.vertices[l.point_vertex2d[i]]))
          isolated_face[i] = f;
  result.point_vertex.assign(spec.points.size(), -1);
  for (int j = 0; j <= l.nslab; ++j) {
    for (int f = 0; f < nf; ++f) {
      if (l.cell(f, j - 1) == l.cell(f, j)) continue;
      PlcFacet facet;
      std::vector<int> ring;
      for (int v : l.arr.faces[f].outer) ring.push_back(v3.at(l, plc, v, j));
      facet.polygons.push_back(ring);
      for (const auto& hole : l.arr.faces[f].holes) {
        ring.clear();
        for (int v : hole) ring.push_back(v3.at(l, plc, v, j));
        facet.polygons.push_back(ring);
        const Ring hole_ring = ring_of(l.g, hole);
        const Vector2d h = point_beside(
            l.g, hole, -1, [&](const Vector2d& p) { return ring_contains(hole_ring, p); });
        facet.holes.emplace_back(h.x(), h.y(), l.z[j]);
      }
      for (size_t i = 0; i < spec.points.size(); ++i) {
        if (isolated_face[i] != f || std::abs(spec.points[i].position.z() - l.z[j]) > tol) continue;
        const int v = v3.at(l, plc, l.point_vertex2d[i], j);
        facet.polygons.push_back({v});
        result.point_vertex[i] = v;
      }
      plc.facets.push_back(std::move(facet));
    }
  }
}

/// A point of empty cell (f, j) outside every surface-file body (`is_free`).
Vector3d hole_point(const core::CaseSpec& spec, const Layers& l, int f, int j,
                    const std::function<bool(const Vector3d&)>& is_free) {
  auto free_in_slab = [&](const Vector2d& q, int j) -> std::optional<Vector3d> {
    for (double s : {0.5, 0.25, 0.75, 0.1, 0.9, 0.02, 0.98}) {
      const Vector3d p(q.x(), q.y(), l.z[j] + s * (l.z[j + 1] - l.z[j]));
      if (is_free(p)) return p;
    }
    return std::nullopt;
  };
  if (const auto p = free_in_slab(l.rep[f], j)) return *p;
  try {
    const Vector2d q = point_beside(l.g, l.arr.faces[f].outer, +1, [&](const Vector2d& c) {
      return face_contains(l.g, l.arr.faces[f], c) && free_in_slab(c, j).has_value();
    });
    return *free_in_slab(q, j);
  } catch (const core::GeometryError&) {
    std::ostringstream msg;
    msg << spec.source.string() << ": a surface-file body fills the empty space near ("
        << l.rep[f].x() << ", " << l.rep[f].y() << ", " << 0.5 * (l.z[j] + l.z[j + 1])
        << ") m so closely that no point of that space is left to mark it empty. Hint: leave "
           "a clear gap around surface-file bodies.";
    throw core::GeometryError(msg.str());
  }
}

/// One region point per filled cell and one hole point per empty cell.
void add_regions_and_holes(const core::CaseSpec& spec, const Layers& l,
                           const std::function<bool(const Vector3d&)>& is_free, Plc& plc) {
  for (int f = 0; f < static_cast<int>(l.arr.faces.size()); ++f) {
    for (int j = 0; j < l.nslab; ++j) {
      const Vector3d p(l.rep[f].x(), l.rep[f].y(), 0.5 * (l.z[j] + l.z[j + 1]));
      const int b = l.label[f][j];
      if (b < 0) {
        plc.holes.push_back(hole_point(spec, l, f, j, is_free));
      } else {
        const double h = spec.bodies[b].max_edge;
        plc.regions.push_back(PlcRegion{p, b, h * h * h / (6.0 * std::sqrt(2.0))});
      }
    }
  }
}

/// Named points not yet placed: a PLC vertex already, or inserted inside a body.
void add_named_points(const core::CaseSpec& spec, const Layers& l, double tol,
                      const LayerVertices& v3, ExtrudedPlc& result) {
  for (size_t i = 0; i < spec.points.size(); ++i) {
    if (result.point_vertex[i] >= 0) continue;
    const auto& pt = spec.points[i];
    int zi = -1;
    for (int j = 0; j <= l.nslab; ++j)
      if (std::abs(l.z[j] - pt.position.z()) <= tol) zi = j;
    if (zi >= 0) {
      if (const int v = v3.find(l.point_vertex2d[i], zi); v >= 0) {
        result.point_vertex[i] = v;
        continue;
      }
    }
    bool inside = false;
    for (const auto& b : spec.bodies)
      inside = inside || body_contains(b, pt.position, spec.mesh.circle_segments);
    if (!inside) throw outside_every_body(spec, pt);
    result.plc.interior_points.push_back(pt.position);
  }
}

/// The PLC of z-extruded bodies only. `is_free` says whether a point of empty space lies outside
/// every surface-file body, so that no hole point falls inside one.
ExtrudedPlc extruded_part(const core::CaseSpec& spec,
                          const std::function<bool(const Vector3d&)>& is_free) {
  const double tol = extrusion_tolerance(spec);
  Layers layers;
  add_cross_section(spec, tol, layers);
  add_breakpoints(spec, tol, layers);
  add_cell_bodies(spec, layers);
  ExtrudedPlc result;
  LayerVertices v3;
  add_side_facets(layers, v3, result.plc);
  add_cap_facets(spec, layers, tol, v3, result);
  add_regions_and_holes(spec, layers, is_free, result.plc);
  add_named_points(spec, layers, tol, v3, result);
  return result;
}

bool is_surface_body(const Body& body) {
  for (const auto* list : {&body.add, &body.subtract})
    for (const auto& p : *list)
      if (p.kind == Primitive::Kind::surface_file) return true;
  return false;
}

/// A surface-file body read and checked, with its bounds.
struct SurfaceBody {
  int body = -1;  /// index into CaseSpec::bodies
  cgal::SurfaceSolid solid;
  Eigen::AlignedBox3d bounds;
};

SurfaceBody surface_body(const core::CaseSpec& spec, int index) {
  const Body& body = spec.bodies[index];
  if (body.add.size() != 1 || !body.subtract.empty() ||
      body.add[0].kind != Primitive::Kind::surface_file) {
    std::ostringstream msg;
    msg << spec.source.string() << ": body '" << body.name << "' uses a surface file but has "
        << body.add.size() << " add and " << body.subtract.size()
        << " subtract entries; a surface-file body is exactly one add entry, the surface, and "
           "nothing else. Hint: give the boxes and cylinders a body of their own, or build the "
           "whole solid in the CAD tool.";
    throw core::GeometryError(msg.str());
  }
  const Primitive& p = body.add[0];
  SurfaceBody s{index, cgal::surface_solid(p.file, p.file_scale, "body '" + body.name + "'"), {}};
  for (const auto& v : s.solid.surface.vertices) s.bounds.extend(v);
  return s;
}

/// Puts vertex v, lying on the segment a-b, into the ring of `facet` that has that edge (in either
/// direction, perhaps already split by earlier points), ordered along it.
void insert_on_edge(PlcFacet& facet, int a, int b, int v, const std::vector<Vector3d>& x) {
  auto between = [&](int w) {
    const Vector3d ab = x[b] - x[a];
    return (x[w] - x[a]).cross(ab).norm() <= 1e-9 * ab.squaredNorm();
  };
  for (auto& ring : facet.polygons)
    for (const auto& [from, to] : {std::pair{a, b}, std::pair{b, a}}) {
      const auto it = std::find(ring.begin(), ring.end(), from);
      if (ring.size() < 3 || it == ring.end()) continue;
      std::vector<int> r = ring;
      std::rotate(r.begin(), r.begin() + (it - ring.begin()), r.end());
      size_t k = 1;
      while (k < r.size() && r[k] != to && between(r[k])) ++k;
      if (k == r.size() || r[k] != to) continue;
      size_t j = 1;
      while (j < k && (x[r[j]] - x[from]).norm() < (x[v] - x[from]).norm()) ++j;
      r.insert(r.begin() + static_cast<std::ptrdiff_t>(j), v);
      ring = r;
      return;
    }
}

/// Edge-connected coplanar triangles of a surface body, handed to TetGen as one facet: separate
/// coplanar triangle facets let its refinement leave zero-volume tets along their shared edges.
struct Patch {
  std::vector<int> triangles;
  std::vector<std::vector<int>> polygons;  /// its boundary ring, or its triangles when not one ring
};

std::vector<Patch> planar_patches(const cgal::TriangleSurface& s, double tol,
                                  std::vector<int>& patch_of) {
  const auto& x = s.vertices;
  const auto& tri = s.triangles;
  const int nt = static_cast<int>(tri.size());
  std::vector<Vector3d> normal(nt);
  std::map<std::pair<int, int>, int> edge_triangle;  // directed edge -> triangle
  for (int t = 0; t < nt; ++t) {
    normal[t] = (x[tri[t][1]] - x[tri[t][0]]).cross(x[tri[t][2]] - x[tri[t][0]]).normalized();
    for (int k = 0; k < 3; ++k) edge_triangle[{tri[t][k], tri[t][(k + 1) % 3]}] = t;
  }
  std::vector<int> root(nt);
  std::iota(root.begin(), root.end(), 0);
  std::function<int(int)> find = [&](int t) { return root[t] == t ? t : root[t] = find(root[t]); };
  for (int t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const int u = edge_triangle.at({tri[t][(k + 1) % 3], tri[t][k]});
      bool flat = normal[t].dot(normal[u]) > 1 - 1e-12;
      for (int c : tri[u]) flat = flat && std::abs(normal[t].dot(x[c] - x[tri[t][0]])) <= tol;
      if (flat) root[find(t)] = find(u);
    }
  std::vector<Patch> patches;
  std::map<int, int> patch_of_root;
  patch_of.assign(nt, -1);
  for (int t = 0; t < nt; ++t) {
    const auto [it, fresh] = patch_of_root.emplace(find(t), static_cast<int>(patches.size()));
    if (fresh) patches.emplace_back();
    patches[it->second].triangles.push_back(t);
    patch_of[t] = it->second;
  }
  for (auto& p : patches) {
    std::map<int, int> next;  // boundary edges of the patch, vertex -> vertex
    bool simple = true;
    for (int t : p.triangles)
      for (int k = 0; k < 3; ++k) {
        const int a = tri[t][k], b = tri[t][(k + 1) % 3];
        if (patch_of[edge_triangle.at({b, a})] == patch_of[t]) continue;
        simple = simple && next.emplace(a, b).second;
      }
    std::vector<int> ring;
    if (simple && !next.empty()) {
      int v = next.begin()->first;
      do {
        ring.push_back(v);
        v = next[v];
      } while (v != ring.front() && ring.size() <= next.size());
      simple = v == ring.front() && ring.size() == next.size();
    }
    if (simple) {
      p.polygons.push_back(ring);
    } else {
      for (int t : p.triangles) p.polygons.push_back({tri[t][0], tri[t][1], tri[t][2]});
    }
  }
  return patches;
}

std::string overlap_message(const core::CaseSpec& spec, const SurfaceBody& s, int other) {
  return spec.source.string() + ": body '" + spec.bodies[s.body].name + "' (" +
         spec.bodies[s.body].add[0].file.string() + ") overlaps or touches body '" +
         spec.bodies[other].name +
         "'. A surface-file body must stand clear of every other body, or lie strictly inside a "
         "subtracted primitive of it; bonded contact with it is not supported. Hint: leave a gap.";
}

/// Throws unless every surface-file body is clear of the other bodies (see overlap_message).
void check_surface_bodies_clear(const core::CaseSpec& spec,
                                const std::vector<SurfaceBody>& surfaces) {
  const int n = spec.mesh.circle_segments;
  for (size_t i = 0; i < surfaces.size(); ++i)
    for (size_t j = i + 1; j < surfaces.size(); ++j)
      if (surfaces[i].bounds.intersects(surfaces[j].bounds) &&
          cgal::solids_meet(surfaces[i].solid.surface, surfaces[j].solid.surface))
        throw core::GeometryError(overlap_message(spec, surfaces[i], surfaces[j].body));
  for (const auto& s : surfaces) {
    for (size_t b = 0; b < spec.bodies.size(); ++b) {
      if (is_surface_body(spec.bodies[b])) continue;
      for (const auto& a : spec.bodies[b].add) {
        if (!primitive_bounds(a).intersects(s.bounds) ||
            !cgal::solids_meet(s.solid.surface, primitive_surface(a, n)))
          continue;
        bool carved_out = false;
        for (const auto& u : spec.bodies[b].subtract)
          carved_out =
              carved_out || (primitive_bounds(u).contains(s.bounds) &&
                             cgal::solid_strictly_inside(s.solid.surface, primitive_surface(u, n)));
        if (!carved_out) throw core::GeometryError(overlap_message(spec, s, static_cast<int>(b)));
      }
    }
  }
}

/// The surface-file bodies of a case, each read and checked.
std::vector<SurfaceBody> surface_bodies(const core::CaseSpec& spec) {
  std::vector<SurfaceBody> surfaces;
  for (size_t b = 0; b < spec.bodies.size(); ++b)
    if (is_surface_body(spec.bodies[b]))
      surfaces.push_back(surface_body(spec, static_cast<int>(b)));
  return surfaces;
}

/// 1e-9 of the diagonal of all bodies' bounds [m].
double geometry_tolerance(const core::CaseSpec& spec, const std::vector<SurfaceBody>& surfaces) {
  Eigen::AlignedBox3d extent;
  for (const auto& s : surfaces) extent.extend(s.bounds);
  for (const auto& b : spec.bodies)
    if (!is_surface_body(b))
      for (const auto& p : b.add) extent.extend(primitive_bounds(p));
  return 1e-9 * extent.diagonal().norm();
}

/// Which surface body each named point lies on or in (the first one that has it), and where.
struct SurfacePoints {
  std::vector<int> surface;                   /// per named point: index into surfaces, or -1
  std::vector<cgal::PointLocation> location;  /// per named point, where surface >= 0
};

SurfacePoints surface_points(const core::CaseSpec& spec, const std::vector<SurfaceBody>& surfaces,
                             double tol) {
  using Kind = cgal::PointLocation::Kind;
  std::vector<Vector3d> positions;
  for (const auto& p : spec.points) positions.push_back(p.position);
  SurfacePoints out{std::vector<int>(spec.points.size(), -1),
                    std::vector<cgal::PointLocation>(spec.points.size())};
  for (size_t s = 0; s < surfaces.size(); ++s) {
    const auto located = cgal::locate_points(surfaces[s].solid.surface, positions, tol);
    for (size_t i = 0; i < located.size(); ++i)
      if (out.surface[i] < 0 && located[i].kind != Kind::outside)
        out.surface[i] = static_cast<int>(s), out.location[i] = located[i];
  }
  return out;
}

/// The case reduced to its z-extruded bodies and the named points off every surface body, with
/// the maps from reduced indices back to the whole case.
struct ExtrudedSubset {
  core::CaseSpec spec;
  std::vector<int> body;   /// reduced body index -> index in the whole case
  std::vector<int> point;  /// reduced point index -> index in the whole case
};

ExtrudedSubset extruded_subset(const core::CaseSpec& spec, const SurfacePoints& on_surface) {
  ExtrudedSubset sub{spec, {}, {}};
  sub.spec.bodies.clear();
  sub.spec.points.clear();
  for (size_t b = 0; b < spec.bodies.size(); ++b)
    if (!is_surface_body(spec.bodies[b])) {
      sub.spec.bodies.push_back(spec.bodies[b]);
      sub.body.push_back(static_cast<int>(b));
    }
  for (size_t i = 0; i < spec.points.size(); ++i)
    if (on_surface.surface[i] < 0) {
      sub.spec.points.push_back(spec.points[i]);
      sub.point.push_back(static_cast<int>(i));
    }
  return sub;
}

/// The PLC of the extruded bodies, with body and point indices mapped back to the whole case
/// (point_vertex has an entry per named point of `spec`); no hole point falls in a surface body.
ExtrudedPlc extruded_subset_plc(const core::CaseSpec& spec, const ExtrudedSubset& sub,
                                const std::vector<SurfaceBody>& surfaces) {
  using Kind = cgal::PointLocation::Kind;
  ExtrudedPlc result;
  result.point_vertex.assign(spec.points.size(), -1);
  if (!sub.spec.bodies.empty()) {
    auto is_free = [&](const Vector3d& p) {
      for (const auto& s : surfaces)
        if (s.bounds.contains(p) &&
            cgal::locate_points(s.solid.surface, {p}, 0.0)[0].kind != Kind::outside)
          return false;
      return true;
    };
    ExtrudedPlc part = extruded_part(sub.spec, is_free);
    for (auto& r : part.plc.regions) r.region = sub.body[r.region];
    for (size_t i = 0; i < sub.point.size(); ++i)
      result.point_vertex[sub.point[i]] = part.point_vertex[i];
    result.plc = std::move(part.plc);
  } else if (!sub.spec.points.empty()) {
    throw outside_every_body(spec, sub.spec.points.front());
  }
  return result;
}

/// Where a surface body's vertices and facets were put in the PLC.
struct PlacedSurface {
  const cgal::TriangleSurface* surface = nullptr;
  std::vector<int> patch_of;  /// per triangle: its patch, whose facet is first_facet + patch
  int first_vertex = 0;
  size_t first_facet = 0;
};

/// Adds a surface's vertices, and each of its planar patches as one facet.
PlacedSurface add_surface_facets(Plc& plc, const cgal::TriangleSurface& surface, double tol) {
  PlacedSurface placed{&surface, {}, static_cast<int>(plc.vertices.size()), plc.facets.size()};
  plc.vertices.insert(plc.vertices.end(), surface.vertices.begin(), surface.vertices.end());
  for (const auto& patch : planar_patches(surface, tol, placed.patch_of)) {
    PlcFacet facet;
    for (const auto& ring : patch.polygons) {
      facet.polygons.emplace_back();
      for (int v : ring) facet.polygons.back().push_back(placed.first_vertex + v);
    }
    plc.facets.push_back(std::move(facet));
  }
  return placed;
}

/// Adds named point x, lying on triangle `t` of a placed surface, as a new vertex, returned. On
/// an edge between two patches the point joins both facets' rings (TetGen crashes on a lone
/// vertex on a facet's boundary); inside a patch it is a lone vertex of its facet.
int add_point_on_triangle(Plc& plc, const PlacedSurface& placed, int t, const Vector3d& x,
                          double tol) {
  const cgal::TriangleSurface& surface = *placed.surface;
  const int first = placed.first_vertex;
  const int v = static_cast<int>(plc.vertices.size());
  plc.vertices.push_back(x);
  const auto& tri = surface.triangles[t];
  const int own = placed.patch_of[t];
  bool on_crease = false;
  for (int k = 0; k < 3 && !on_crease; ++k) {
    const int a = tri[k], b = tri[(k + 1) % 3];
    const Vector3d& xa = surface.vertices[a];
    const Vector3d& xb = surface.vertices[b];
    const double s = std::clamp((x - xa).dot(xb - xa) / (xb - xa).squaredNorm(), 0.0, 1.0);
    if ((xa + s * (xb - xa) - x).norm() > tol) continue;
    for (size_t f = 0; f < surface.triangles.size(); ++f) {
      const auto& u = surface.triangles[f];
      for (int e = 0; e < 3; ++e)
        if (u[e] == b && u[(e + 1) % 3] == a && placed.patch_of[f] != own) {
          on_crease = true;
          insert_on_edge(plc.facets[placed.first_facet + own], first + a, first + b, v,
                         plc.vertices);
          insert_on_edge(plc.facets[placed.first_facet + placed.patch_of[f]], first + a, first + b,
                         v, plc.vertices);
        }
    }
  }
  if (!on_crease) plc.facets[placed.first_facet + own].polygons.push_back({v});
  return v;
}

/// Adds surface body `s`: its triangles as facets, its named points and a region point.
void add_surface_body(const core::CaseSpec& spec, const SurfaceBody& body, int s,
                      const SurfacePoints& on_surface, double tol, ExtrudedPlc& result) {
  using Kind = cgal::PointLocation::Kind;
  Plc& plc = result.plc;
  const cgal::SurfaceSolid& solid = body.solid;
  const PlacedSurface placed = add_surface_facets(plc, solid.surface, tol);
  for (size_t i = 0; i < spec.points.size(); ++i) {
    if (on_surface.surface[i] != s) continue;
    const Vector3d& x = spec.points[i].position;
    const cgal::PointLocation& at = on_surface.location[i];
    switch (at.kind) {
      case Kind::vertex:  // moved by at most tol so that the point is exact
        result.point_vertex[i] = placed.first_vertex + at.index;
        plc.vertices[result.point_vertex[i]] = x;
        break;
      case Kind::triangle:
        result.point_vertex[i] = add_point_on_triangle(plc, placed, at.index, x, tol);
        break;
      case Kind::inside:
        plc.interior_points.push_back(x);
        break;
      case Kind::outside:
        break;
    }
  }
  const double h = spec.bodies[body.body].max_edge;
  plc.regions.push_back(
      PlcRegion{solid.inside_point, body.body, h * h * h / (6.0 * std::sqrt(2.0))});
}

}  // namespace

ExtrudedPlc extruded_plc(const core::CaseSpec& spec) {
  // Surface-file bodies are read and checked; the others go to the extrusion.
  const std::vector<SurfaceBody> surfaces = surface_bodies(spec);
  if (surfaces.empty()) return extruded_part(spec, [](const Vector3d&) { return true; });
  check_surface_bodies_clear(spec, surfaces);
  // Named points on or in a surface body belong to it; the others to the extrusion.
  const double tol = geometry_tolerance(spec, surfaces);
  const SurfacePoints on_surface = surface_points(spec, surfaces, tol);
  ExtrudedPlc result = extruded_subset_plc(spec, extruded_subset(spec, on_surface), surfaces);
  for (size_t s = 0; s < surfaces.size(); ++s)
    add_surface_body(spec, surfaces[s], static_cast<int>(s), on_surface, tol, result);
  return result;
}

}  // namespace tt::mesh
