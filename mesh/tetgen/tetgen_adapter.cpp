#include "mesh/tetgen/tetgen_adapter.hpp"

#include <tetgen.h>

#include <Eigen/Geometry>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.hpp"

namespace tt::mesh::tetgen {
namespace {

std::string error_text(int code) {
  switch (code) {
    case 1: return "out of memory";
    case 2: return "internal error (please report)";
    case 3: return "a self-intersection was detected in the input (facets cross each other)";
    case 4: return "a very small input feature size was detected (points or facets nearly touch)";
    case 5: return "two very close input facets were detected";
    case 10: return "an input error was detected";
    default: return "failure code " + std::to_string(code);
  }
}

/// Copies the PLC into TetGen's structures; tetgenio frees them with delete[].
void fill_input(const Plc& plc, tetgenio& in) {
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(plc.vertices.size());
  in.pointlist = new REAL[3 * plc.vertices.size()];
  for (size_t i = 0; i < plc.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) in.pointlist[3 * i + k] = plc.vertices[i][k];

  in.numberoffacets = static_cast<int>(plc.facets.size());
  in.facetlist = new tetgenio::facet[plc.facets.size()];
  in.facetmarkerlist = new int[plc.facets.size()];
  for (size_t f = 0; f < plc.facets.size(); ++f) {
    const PlcFacet& src = plc.facets[f];
    tetgenio::facet& dst = in.facetlist[f];
    tetgenio::init(&dst);
    dst.numberofpolygons = static_cast<int>(src.polygons.size());
    dst.polygonlist = new tetgenio::polygon[src.polygons.size()];
    for (size_t p = 0; p < src.polygons.size(); ++p) {
      tetgenio::polygon& poly = dst.polygonlist[p];
      tetgenio::init(&poly);
      poly.numberofvertices = static_cast<int>(src.polygons[p].size());
      poly.vertexlist = new int[src.polygons[p].size()];
      for (size_t v = 0; v < src.polygons[p].size(); ++v) poly.vertexlist[v] = src.polygons[p][v];
    }
    if (!src.holes.empty()) {
      dst.numberofholes = static_cast<int>(src.holes.size());
      dst.holelist = new REAL[3 * src.holes.size()];
      for (size_t h = 0; h < src.holes.size(); ++h)
        for (int k = 0; k < 3; ++k) dst.holelist[3 * h + k] = src.holes[h][k];
    }
    in.facetmarkerlist[f] = static_cast<int>(f) + 1;
  }

  if (!plc.holes.empty()) {
    in.numberofholes = static_cast<int>(plc.holes.size());
    in.holelist = new REAL[3 * plc.holes.size()];
    for (size_t h = 0; h < plc.holes.size(); ++h)
      for (int k = 0; k < 3; ++k) in.holelist[3 * h + k] = plc.holes[h][k];
  }
  in.numberofregions = static_cast<int>(plc.regions.size());
  in.regionlist = new REAL[5 * plc.regions.size()];
  for (size_t r = 0; r < plc.regions.size(); ++r) {
    for (int k = 0; k < 3; ++k) in.regionlist[5 * r + k] = plc.regions[r].point[k];
    in.regionlist[5 * r + 3] = plc.regions[r].region + 1;  // 0 means "no region" in TetGen
    in.regionlist[5 * r + 4] = plc.regions[r].max_volume;
  }
}

std::string switches_for(const TetgenOptions& options) {
  std::ostringstream s;
  // p: PLC, z: zero-based, A: region attributes, a: region volume bounds, q: quality, Q: quiet.
  s << "pzAaQq" << options.radius_edge_ratio << "/" << options.min_dihedral_deg;
  return s.str();
}

}  // namespace

LinearTets tetrahedralize(const Plc& plc, const TetgenOptions& options) {
  if (!(options.radius_edge_ratio >= 1.0) || !(options.min_dihedral_deg >= 0.0) ||
      options.min_dihedral_deg > 18.0)
    throw core::MeshError("mesh quality bounds radius_edge_ratio = " +
                          std::to_string(options.radius_edge_ratio) + ", min_dihedral_deg = " +
                          std::to_string(options.min_dihedral_deg) +
                          ": need radius_edge_ratio >= 1 and 0 <= min_dihedral_deg <= 18");
  // Interior points go in as isolated PLC vertices: TetGen keeps every input vertex inside the
  // domain, and its -i insertion path crashes in 1.5.0.
  Plc with_points = plc;
  with_points.vertices.insert(with_points.vertices.end(), plc.interior_points.begin(),
                              plc.interior_points.end());
  tetgenio in, out;
  fill_input(with_points, in);
  std::string switches = switches_for(options);
  std::vector<char> buffer(switches.begin(), switches.end());
  buffer.push_back('\0');
  try {
    ::tetrahedralize(buffer.data(), &in, &out);
  } catch (int code) {
    throw core::MeshError("TetGen failed with switches '" + switches + "' on a PLC of " +
                          std::to_string(plc.vertices.size()) + " vertices and " +
                          std::to_string(plc.facets.size()) + " facets: " + error_text(code) +
                          ". Hint: check that bodies do not nearly touch, coarsen circle_segments "
                          "or relax the quality bounds.");
  }
  if (out.numberoftetrahedra == 0 || out.numberofcorners != 4)
    throw core::MeshError("TetGen returned no tetrahedra for switches '" + switches + "'");
  if (out.numberoftetrahedronattributes < 1)
    throw core::MeshError("TetGen returned tetrahedra without region attributes");

  LinearTets result;
  result.nodes.resize(out.numberofpoints);
  for (int i = 0; i < out.numberofpoints; ++i)
    result.nodes[i] = {out.pointlist[3 * i], out.pointlist[3 * i + 1], out.pointlist[3 * i + 2]};
  result.tets.resize(out.numberoftetrahedra);
  result.region.resize(out.numberoftetrahedra);
  const int na = out.numberoftetrahedronattributes;
  for (int t = 0; t < out.numberoftetrahedra; ++t) {
    std::array<int, 4> tet;
    for (int k = 0; k < 4; ++k) tet[k] = out.tetrahedronlist[4 * t + k];
    const Eigen::Vector3d& a = result.nodes[tet[0]];
    const double orient = (result.nodes[tet[1]] - a)
                              .cross(result.nodes[tet[2]] - a)
                              .dot(result.nodes[tet[3]] - a);
    if (orient < 0) std::swap(tet[2], tet[3]);
    result.tets[t] = tet;
    const int attribute = static_cast<int>(out.tetrahedronattributelist[na * t] + 0.5);
    if (attribute < 1)
      throw core::MeshError("TetGen produced tetrahedron " + std::to_string(t) +
                            " outside every declared body (region attribute " +
                            std::to_string(attribute) + "); a region point is missing");
    result.region[t] = attribute - 1;
  }
  return result;
}

}  // namespace tt::mesh::tetgen
