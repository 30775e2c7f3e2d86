// Fixtures for the mesh tests: a temporary folder per test, small case files around a few bodies,
// and closed (or deliberately broken) surfaces written as STL, OFF or PLY text.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/common/case_toml.hpp"

namespace tt::mesh::test {

namespace fs = std::filesystem;

/// A folder under the system temp dir, named after the running test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info ? std::string(info->test_suite_name()) + "_" + info->name() : "suite";
    for (char& c : name)
      if (c == '/') c = '_';
    path_ = fs::temp_directory_path() / ("tt_mesh_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path p = path_ / name;
    std::ofstream(p) << text;
    return p;
  }

 private:
  fs::path path_;
};

/// A polygon soup: vertices and faces (counter-clockwise seen from outside when outward).
struct Soup {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> faces;
};

/// The axis-aligned cube [lo, lo + size]^3 as six outward quads.
inline Soup cube(const Eigen::Vector3d& lo, double size) {
  Soup s;
  for (int k = 0; k < 8; ++k)
    s.vertices.push_back(lo + size * Eigen::Vector3d(k & 1, (k >> 1) & 1, (k >> 2) & 1));
  s.faces = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  return s;
}

/// A z-parallel prism over a regular n-gon of circumradius r (a faceted cylinder): n-gon caps
/// and quad sides, so readers must triangulate.
inline Soup prism(const Eigen::Vector2d& axis, double r, double z0, double z1, int n) {
  Soup s;
  for (double z : {z0, z1})
    for (int k = 0; k < n; ++k) {
      const double a = 2 * M_PI * k / n;
      s.vertices.emplace_back(axis.x() + r * std::cos(a), axis.y() + r * std::sin(a), z);
    }
  std::vector<int> bottom, top;
  for (int k = 0; k < n; ++k) {
    bottom.push_back(n - 1 - k);
    top.push_back(n + k);
    s.faces.push_back({k, (k + 1) % n, n + (k + 1) % n, n + k});
  }
  s.faces.push_back(bottom);
  s.faces.push_back(top);
  return s;
}

/// Exact volume of prism(axis, r, z0, z1, n).
inline double prism_volume(double r, double z0, double z1, int n) {
  return 0.5 * n * r * r * std::sin(2 * M_PI / n) * (z1 - z0);
}

inline Soup merged(const Soup& a, const Soup& b) {
  Soup s = a;
  const int off = static_cast<int>(a.vertices.size());
  s.vertices.insert(s.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto f : b.faces) {
    for (int& v : f) v += off;
    s.faces.push_back(f);
  }
  return s;
}

inline Soup reversed(Soup s) {
  for (auto& f : s.faces) std::reverse(f.begin(), f.end());
  return s;
}

inline Soup without_face(Soup s, int face) {
  s.faces.erase(s.faces.begin() + face);
  return s;
}

inline std::string number(double x) {
  std::ostringstream o;
  o.precision(17);
  o << x;
  return o.str();
}

/// ASCII STL: every face fanned into triangles.
inline std::string stl_text(const Soup& s) {
  std::ostringstream o;
  o << "solid fixture\n";
  for (const auto& f : s.faces)
    for (size_t k = 1; k + 1 < f.size(); ++k) {
      const Eigen::Vector3d &a = s.vertices[f[0]], &b = s.vertices[f[k]], &c = s.vertices[f[k + 1]];
      const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
      o << "facet normal " << number(n.x()) << " " << number(n.y()) << " " << number(n.z())
        << "\n  outer loop\n";
      for (const auto* p : {&a, &b, &c})
        o << "    vertex " << number(p->x()) << " " << number(p->y()) << " " << number(p->z())
          << "\n";
      o << "  endloop\nendfacet\n";
    }
  o << "endsolid fixture\n";
  return o.str();
}

inline std::string off_text(const Soup& s) {
  std::ostringstream o;
  o << "OFF\n" << s.vertices.size() << " " << s.faces.size() << " 0\n";
  for (const auto& v : s.vertices)
    o << number(v.x()) << " " << number(v.y()) << " " << number(v.z()) << "\n";
  for (const auto& f : s.faces) {
    o << f.size();
    for (int v : f) o << " " << v;
    o << "\n";
  }
  return o.str();
}

inline std::string ply_text(const Soup& s) {
  std::ostringstream o;
  o << "ply\nformat ascii 1.0\nelement vertex " << s.vertices.size()
    << "\nproperty double x\nproperty double y\nproperty double z\nelement face " << s.faces.size()
    << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& v : s.vertices)
    o << number(v.x()) << " " << number(v.y()) << " " << number(v.z()) << "\n";
  for (const auto& f : s.faces) {
    o << f.size();
    for (int v : f) o << " " << v;
    o << "\n";
  }
  return o.str();
}

/// A complete small case around `bodies` ([[bodies]] tables using material "steel") and an
/// optional [points] list, lengths in `unit`, with one catch-all boundary group "outside".
inline std::string small_case(const std::string& bodies, const std::string& points = "",
                              const std::string& unit = "m", const std::string& mesh = "") {
  std::ostringstream o;
  o << "[case]\nname = \"mesh test\"\n\n[geometry]\nlength_unit = \"" << unit << "\"\n\n"
    << test_toml::steel() << "\n"
    << bodies << "\n\n[mesh]\norder = 1\n"
    << mesh << "\n"
    << "[[boundary]]\nname = \"outside\"\nselect = [ {} ]\n\n";
  if (!points.empty()) o << "[points]\nlist = [\n" << points << "\n]\n\n";
  o << "[duty_cycle]\nend_s = 60.0\nsegments = [ { start_s = 0.0, speed_rpm = 0.0 } ]\n\n"
    << "[mechanical]\nenabled = false\n";
  return o.str();
}

}  // namespace tt::mesh::test
