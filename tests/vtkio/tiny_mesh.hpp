// Hand-built meshes and scratch directories shared by the writer tests.
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <utility>

#include "mesh/tet_mesh.hpp"

namespace tt::test {

/// An empty directory for one test, under the build tree.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::path(TT_BINARY_DIR) / "test_output" / "vtkio" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Two linear tets sharing the face (1,2,3): tet 0 in region "housing", tet 1 in "spindle".
/// Seven faces: six exterior, one interface; groups "base" (1 face) and "bore" (2 faces).
inline mesh::TetMesh two_tets() {
  mesh::TetMesh m;
  m.order = 1;
  m.nodes.resize(5, 3);
  m.nodes << 0, 0, 0,  //
      1, 0, 0,         //
      0, 1, 0,         //
      0, 0, 1,         //
      1, 1, 1;
  m.corner_count = 5;
  m.tets.resize(2, 4);
  m.tets << 0, 1, 2, 3,  //
      1, 2, 3, 4;
  m.tet_region = {core::RegionId{0}, core::RegionId{1}};
  m.region_names = {"housing", "spindle"};
  m.faces.resize(7, 3);
  m.faces << 0, 2, 1,  //
      0, 1, 3,         //
      0, 3, 2,         //
      1, 2, 3,         // interface
      2, 3, 4,         //
      1, 4, 3,         //
      1, 2, 4;
  m.face_tet = {0, 0, 0, 0, 1, 1, 1};
  m.face_other_tet = {-1, -1, -1, 1, -1, -1, -1};
  const auto none = core::BoundaryId{-1};
  m.face_group = {core::BoundaryId{0}, none, none, none, core::BoundaryId{1},
                  core::BoundaryId{1}, none};
  m.group_names = {"base", "bore"};
  m.points = {{"T02", Eigen::Vector3d(1, 1, 1), 4},
              {"TCP", Eigen::Vector3d(0, 0, 0), 0},
              {"free", Eigen::Vector3d(0.2, 0.2, 0.2), -1}};
  return m;
}

/// `linear` with a node added at the middle of every edge, numbered after the corners.
inline mesh::TetMesh quadratic(const mesh::TetMesh& linear) {
  constexpr std::array<std::pair<int, int>, 6> tet_edges = {
      {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}}};
  mesh::TetMesh m = linear;
  m.order = 2;
  std::map<std::pair<int, int>, int> mid;
  std::vector<Eigen::RowVector3d> extra;
  const auto mid_node = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    const auto found = mid.find(key);
    if (found != mid.end()) return found->second;
    const int node = static_cast<int>(linear.nodes.rows() + extra.size());
    extra.push_back(0.5 * (linear.nodes.row(a) + linear.nodes.row(b)));
    mid.emplace(key, node);
    return node;
  };
  m.tets.resize(linear.tets.rows(), 10);
  for (Eigen::Index t = 0; t < linear.tets.rows(); ++t) {
    for (int k = 0; k < 4; ++k) m.tets(t, k) = linear.tets(t, k);
    for (int e = 0; e < 6; ++e) {
      m.tets(t, 4 + e) =
          mid_node(linear.tets(t, tet_edges[e].first), linear.tets(t, tet_edges[e].second));
    }
  }
  m.faces.resize(linear.faces.rows(), 6);
  for (Eigen::Index f = 0; f < linear.faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) m.faces(f, k) = linear.faces(f, k);
    for (int k = 0; k < 3; ++k) {
      m.faces(f, 3 + k) = mid_node(linear.faces(f, k), linear.faces(f, (k + 1) % 3));
    }
  }
  m.nodes.resize(linear.nodes.rows() + static_cast<Eigen::Index>(extra.size()), 3);
  m.nodes.topRows(linear.nodes.rows()) = linear.nodes;
  for (std::size_t i = 0; i < extra.size(); ++i) m.nodes.row(linear.nodes.rows() + i) = extra[i];
  m.corner_count = static_cast<int>(linear.nodes.rows());
  return m;
}

}  // namespace tt::test
