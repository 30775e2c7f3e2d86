#include "mesh/extrusion.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <Eigen/Geometry>
#include <map>
#include <numeric>
#include <sstream>

#include "core/errors.hpp"

namespace tt::mesh {
namespace {

using core::Body;
using core::Primitive;
using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kPi = 3.14159265358979323846;

/// A closed ring of 2D points, counter-clockwise.
using Ring = std::vector<Vector2d>;

double cross2(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

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
      return {Ring{{p.min.x(), p.min.y()}, {p.max.x(), p.min.y()}, {p.max.x(), p.max.y()},
                   {p.min.x(), p.max.y()}},
              {}};
    case Primitive::Kind::cylinder:
      return {faceted_circle(p.axis, p.radius, n), {}};
    case Primitive::Kind::annulus:
      return {faceted_circle(p.axis, p.radius, n), faceted_circle(p.axis, p.inner_radius, n)};
    case Primitive::Kind::surface_file:
      break;
  }
  throw core::GeometryError(p.where + ": surface-file primitives cannot be combined with "
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
  std::vector<int> halfedge_face;  /// per half-edge 2e (a->b) and 2e+1 (b->a): face on its left, -1 unbounded
};

Ring ring_of(const Pslg& g, const std::vector<int>& ids) {
  Ring r;
  for (int i : ids) r.push_back(g.vertices[i]);
  return r;
}

Arrangement arrangement(const Pslg& g) {
  const int nv = static_cast<int>(g.vertices.size());
  const int nh = 2 * static_cast<int>(g.edges.size());
  auto origin = [&](int h) { return g.edges[h / 2][h % 2]; };
  auto dest = [&](int h) { return g.edges[h / 2][1 - h % 2]; };
  std::vector<std::vector<int>> out(nv);
  for (int h = 0; h < nh; ++h) out[origin(h)].push_back(h);
  for (int v = 0; v < nv; ++v) {
    auto angle = [&](int h) {
      const Vector2d d = g.vertices[dest(h)] - g.vertices[v];
      return std::atan2(d.y(), d.x());
    };
    std::sort(out[v].begin(), out[v].end(), [&](int a, int b) { return angle(a) < angle(b); });
  }
  std::vector<int> pos(nh);
  for (int v = 0; v < nv; ++v)
    for (size_t k = 0; k < out[v].size(); ++k) pos[out[v][k]] = static_cast<int>(k);
  auto next = [&](int h) {
    const int v = dest(h);
    const int twin = h ^ 1;
    const int deg = static_cast<int>(out[v].size());
    return out[v][(pos[twin] - 1 + deg) % deg];
  };

  // Components, for telling a hole's container from its own outer cycle.
  std::vector<int> comp(nv);
  std::iota(comp.begin(), comp.end(), 0);
  std::function<int(int)> find = [&](int x) { return comp[x] == x ? x : comp[x] = find(comp[x]); };
  for (const auto& e : g.edges) comp[find(e[0])] = find(e[1]);

  struct Cycle {
    std::vector<int> halfedges;
    std::vector<int> ring;
    double area;
    int component;
  };
  std::vector<Cycle> cycles;
  std::vector<int> cycle_of(nh, -1);
  for (int h0 = 0; h0 < nh; ++h0) {
    if (cycle_of[h0] >= 0) continue;
    Cycle c;
    int h = h0;
    do {
      cycle_of[h] = static_cast<int>(cycles.size());
      c.halfedges.push_back(h);
      c.ring.push_back(origin(h));
      h = next(h);
    } while (h != h0);
    c.area = signed_area(ring_of(g, c.ring));
    c.component = find(c.ring[0]);
    cycles.push_back(std::move(c));
  }

  Arrangement arr;
  std::vector<int> face_of_cycle(cycles.size(), -1);
  for (size_t c = 0; c < cycles.size(); ++c) {
    if (cycles[c].area > 0) {
      face_of_cycle[c] = static_cast<int>(arr.faces.size());
      arr.faces.push_back(Face{cycles[c].ring, {}});
    }
  }
  for (size_t c = 0; c < cycles.size(); ++c) {
    if (cycles[c].area > 0) continue;
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
    if (best >= 0) {
      face_of_cycle[c] = face_of_cycle[best];
      arr.faces[face_of_cycle[best]].holes.push_back(cycles[c].ring);
    }
  }
  arr.halfedge_face.assign(nh, -1);
  for (int h = 0; h < nh; ++h) arr.halfedge_face[h] = face_of_cycle[cycle_of[h]];
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
  throw core::GeometryError("could not find an interior point of a cross-section face; the "
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

}  // namespace

double faceted_radius(double r, int n) {
  const double a = 2 * kPi / n;
  return r * std::sqrt(a / std::sin(a));
}

std::vector<Vector2d> faceted_circle(const Vector2d& centre, double r, int n) {
  const double rf = faceted_radius(r, n);
  std::vector<Vector2d> ring(n);
  for (int k = 0; k < n; ++k) {
    const double a = 2 * kPi * k / n;
    ring[k] = centre + rf * Vector2d(std::cos(a), std::sin(a));
  }
  return ring;
}

bool body_contains(const Body& body, const Vector3d& p, int circle_segments) {
  return body_contains_tol(body, p, circle_segments, 1e-9, -1.0);
}

double exact_body_volume(const Body& body) {
  auto volume = [](const Primitive& p) {
    switch (p.kind) {
      case Primitive::Kind::box: return (p.max - p.min).prod();
      case Primitive::Kind::cylinder: return kPi * p.radius * p.radius * (p.z_max - p.z_min);
      case Primitive::Kind::annulus:
        return kPi * (p.radius * p.radius - p.inner_radius * p.inner_radius) * (p.z_max - p.z_min);
      default: return -1.0;
    }
  };
  auto bounds = [](const Primitive& p) {
    Eigen::AlignedBox3d b;
    if (p.kind == Primitive::Kind::box) return Eigen::AlignedBox3d(p.min, p.max);
    const double r = p.radius;
    return Eigen::AlignedBox3d(Vector3d(p.axis.x() - r, p.axis.y() - r, p.z_min),
                               Vector3d(p.axis.x() + r, p.axis.y() + r, p.z_max));
  };
  if (body.add.size() != 1) return -1;
  double v = volume(body.add[0]);
  if (v < 0) return -1;
  const auto outer = bounds(body.add[0]);
  for (size_t i = 0; i < body.subtract.size(); ++i) {
    const auto& s = body.subtract[i];
    if (body.add[0].kind != Primitive::Kind::box || s.kind == Primitive::Kind::surface_file)
      return -1;
    if (!outer.contains(bounds(s))) return -1;
    for (size_t j = 0; j < i; ++j)
      if (!bounds(s).intersection(bounds(body.subtract[j])).isEmpty()) return -1;
    v -= volume(s);
  }
  return v;
}

ExtrudedPlc extruded_plc(const core::CaseSpec& spec) {
  const int n = spec.mesh.circle_segments;
  // 1. Extent and tolerance.
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
  if (extent.isEmpty()) throw core::GeometryError(spec.source.string() + ": the case has no bodies");
  const double tol = 1e-9 * extent.diagonal().norm();

  // 2. The planar graph: named points first so that their coordinates are kept exactly.
  Pslg g;
  g.tol = tol;
  std::vector<int> point_vertex2d;
  for (const auto& p : spec.points) point_vertex2d.push_back(g.vertex(p.position.head<2>()));
  for (const auto& b : spec.bodies)
    for (const auto* list : {&b.add, &b.subtract})
      for (const auto& p : *list) {
        const auto [outer, inner] = primitive_rings(p, n);
        for (const Ring* r : {&outer, &inner}) {
          std::vector<int> ids;
          for (const auto& q : *r) ids.push_back(g.vertex(q));
          for (size_t i = 0; i < ids.size(); ++i) g.edges.push_back({ids[i], ids[(i + 1) % ids.size()]});
        }
      }
  resolve_pslg(g);
  const Arrangement arr = arrangement(g);
  std::vector<int> degree(g.vertices.size(), 0);
  for (const auto& e : g.edges) ++degree[e[0]], ++degree[e[1]];

  // 3. Breakpoints along z: primitive ends and the heights of named points on vertical faces.
  std::vector<ZValue> zs;
  for (const auto& b : spec.bodies)
    for (const auto* list : {&b.add, &b.subtract})
      for (const auto& p : *list) {
        const auto [z0, z1] = z_range(p);
        zs.push_back({z0, false});
        zs.push_back({z1, false});
      }
  for (size_t i = 0; i < spec.points.size(); ++i)
    if (degree[point_vertex2d[i]] > 0) zs.push_back({spec.points[i].position.z(), true});
  const std::vector<double> z = merged_breakpoints(zs, tol);
  const int nslab = static_cast<int>(z.size()) - 1;

  // 4. Representative points and the body of every (face, slab) cell.
  const int nf = static_cast<int>(arr.faces.size());
  std::vector<Vector2d> rep(nf);
  for (int f = 0; f < nf; ++f)
    rep[f] = point_beside(g, arr.faces[f].outer, +1,
                          [&](const Vector2d& p) { return face_contains(g, arr.faces[f], p); });
  std::vector<std::vector<int>> label(nf, std::vector<int>(nslab, -1));
  for (int f = 0; f < nf; ++f) {
    for (int j = 0; j < nslab; ++j) {
      const Vector3d p(rep[f].x(), rep[f].y(), 0.5 * (z[j] + z[j + 1]));
      for (size_t b = 0; b < spec.bodies.size(); ++b) {
        if (!body_contains_tol(spec.bodies[b], p, n, 0.0, 0.0)) continue;
        if (label[f][j] >= 0) {
          std::ostringstream msg;
          msg << spec.source.string() << ": bodies '" << spec.bodies[label[f][j]].name << "' and '"
              << spec.bodies[b].name << "' overlap near (" << p.x() << ", " << p.y() << ", "
              << p.z() << ") m without a declared subtraction. Hint: subtract one from the other, "
              << "or make them only touch.";
          throw core::GeometryError(msg.str());
        }
        label[f][j] = static_cast<int>(b);
      }
    }
  }
  auto cell = [&](int f, int j) { return f < 0 || j < 0 || j >= nslab ? -1 : label[f][j]; };

  // 5. Facets.
  ExtrudedPlc result;
  Plc& plc = result.plc;
  std::map<std::pair<int, int>, int> vertex3d;
  auto v3 = [&](int v2, int zi) {
    auto [it, fresh] = vertex3d.emplace(std::make_pair(v2, zi), static_cast<int>(plc.vertices.size()));
    if (fresh) plc.vertices.emplace_back(g.vertices[v2].x(), g.vertices[v2].y(), z[zi]);
    return it->second;
  };
  for (size_t e = 0; e < g.edges.size(); ++e) {
    const int fl = arr.halfedge_face[2 * e], fr = arr.halfedge_face[2 * e + 1];
    for (int j = 0; j < nslab; ++j) {
      if (cell(fl, j) == cell(fr, j)) continue;
      const int a = g.edges[e][0], b = g.edges[e][1];
      plc.facets.push_back(PlcFacet{{{v3(a, j), v3(b, j), v3(b, j + 1), v3(a, j + 1)}}, {}});
    }
  }
  // Named points floating inside a horizontal face.
  std::vector<int> isolated_face(spec.points.size(), -1);
  for (size_t i = 0; i < spec.points.size(); ++i)
    if (degree[point_vertex2d[i]] == 0)
      for (int f = 0; f < nf; ++f)
        if (face_contains(g, arr.faces[f], g.vertices[point_vertex2d[i]])) isolated_face[i] = f;
  result.point_vertex.assign(spec.points.size(), -1);
  for (int j = 0; j <= nslab; ++j) {
    for (int f = 0; f < nf; ++f) {
      if (cell(f, j - 1) == cell(f, j)) continue;
      PlcFacet facet;
      std::vector<int> ring;
      for (int v : arr.faces[f].outer) ring.push_back(v3(v, j));
      facet.polygons.push_back(ring);
      for (const auto& hole : arr.faces[f].holes) {
        ring.clear();
        for (int v : hole) ring.push_back(v3(v, j));
        facet.polygons.push_back(ring);
        const Ring hole_ring = ring_of(g, hole);
        const Vector2d h = point_beside(g, hole, -1, [&](const Vector2d& p) {
          return ring_contains(hole_ring, p);
        });
        facet.holes.emplace_back(h.x(), h.y(), z[j]);
      }
      for (size_t i = 0; i < spec.points.size(); ++i) {
        if (isolated_face[i] != f || std::abs(spec.points[i].position.z() - z[j]) > tol) continue;
        const int v = v3(point_vertex2d[i], j);
        facet.polygons.push_back({v});
        result.point_vertex[i] = v;
      }
      plc.facets.push_back(std::move(facet));
    }
  }

  // 6. Regions and holes, one point per cell.
  for (int f = 0; f < nf; ++f) {
    for (int j = 0; j < nslab; ++j) {
      const Vector3d p(rep[f].x(), rep[f].y(), 0.5 * (z[j] + z[j + 1]));
      const int b = label[f][j];
      if (b < 0) {
        plc.holes.push_back(p);
      } else {
        const double h = spec.bodies[b].max_edge;
        plc.regions.push_back(PlcRegion{p, b, h * h * h / (6.0 * std::sqrt(2.0))});
      }
    }
  }

  // 7. Named points: a PLC vertex already, or inserted inside a body.
  for (size_t i = 0; i < spec.points.size(); ++i) {
    if (result.point_vertex[i] >= 0) continue;
    const auto& pt = spec.points[i];
    int zi = -1;
    for (int j = 0; j <= nslab; ++j)
      if (std::abs(z[j] - pt.position.z()) <= tol) zi = j;
    if (zi >= 0) {
      auto it = vertex3d.find({point_vertex2d[i], zi});
      if (it != vertex3d.end()) {
        result.point_vertex[i] = it->second;
        continue;
      }
    }
    bool inside = false;
    for (const auto& b : spec.bodies) inside = inside || body_contains(b, pt.position, n);
    if (!inside) {
      std::ostringstream msg;
      msg << spec.source.string() << ": points.list '" << pt.id << "' at (" << pt.position.x()
          << ", " << pt.position.y() << ", " << pt.position.z()
          << ") m is outside every body. Hint: check its coordinates and the length unit.";
      throw core::GeometryError(msg.str());
    }
    plc.interior_points.push_back(pt.position);
  }
  return result;
}

}  // namespace tt::mesh
