// Shared pieces of the thermal verification tests: case text for z-extruded boxes, one call from
// case text to a temperature history, and the analytic solutions the tests compare against.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/thermal.hpp"

namespace tt::thermal_test {

constexpr double kPi = 3.14159265358979323846;

/// A number as TOML text that reads back to the same double.
inline std::string num(double v) {
  std::ostringstream s;
  s << std::setprecision(17) << v;
  std::string t = s.str();
  if (t.find_first_of(".eEn") == std::string::npos) t += ".0";
  return t;
}

/// "[x, y, z]" in TOML.
inline std::string vec3(double x, double y, double z) {
  return "[" + num(x) + ", " + num(y) + ", " + num(z) + "]";
}

/// A sink table [[t_s, degC], ...] sampling f(t) [degC] at n + 1 equal intervals of [0, end].
template <class F>
std::string sink_table(F f, double end, int n) {
  std::string s = "[";
  for (int i = 0; i <= n; ++i) {
    const double t = end * i / n;
    s += (i ? ", [" : "[") + num(t) + ", " + num(f(t)) + "]";
  }
  return s + "]";
}

/// Material and one box body named "bar" from `min` to `max` [m]; the caller appends boundary
/// groups, points, [thermal] and [duty_cycle].
struct BoxCase {
  Eigen::Vector3d min = Eigen::Vector3d::Zero(), max = Eigen::Vector3d::Ones();
  double max_edge = 0.1;  /// [m]
  int order = 1;
  double density = 7200;         /// [kg/m^3]
  double specific_heat = 440.5;  /// [J/(kg K)]
  double conductivity = 35;      /// [W/(m K)]
  std::string extra;             /// TOML appended after the body and [mesh]

  std::string toml() const {
    std::string t = "[case]\nname = \"thermal verification\"\n[geometry]\nlength_unit = \"m\"\n";
    t += "[materials.m]\ndensity_kg_m3 = " + num(density) +
         "\nspecific_heat_J_kgK = " + num(specific_heat) +
         "\nconductivity_W_mK = " + num(conductivity) +
         "\nyoungs_modulus_Pa = 2.0e11\npoisson_ratio = 0.3\nexpansion_per_K = 1.2e-5\n";
    t += "[[bodies]]\nname = \"bar\"\nmaterial = \"m\"\nmax_edge = " + num(max_edge) +
         "\nadd = [ { box = { min = " + vec3(min.x(), min.y(), min.z()) +
         ", max = " + vec3(max.x(), max.y(), max.z()) + " } } ]\n";
    t += "[mesh]\norder = " + std::to_string(order) + "\n";
    t += "[mechanical]\nenabled = false\n";
    return t + extra;
  }
};

/// A boundary group of the exterior faces of "bar" in the plane normal . x = offset.
inline std::string plane_group(const std::string& name, const Eigen::Vector3d& normal,
                               double offset) {
  return "[[boundary]]\nname = \"" + name + "\"\nselect = [ { bodies = [\"bar\"], plane = { " +
         "normal = " + vec3(normal.x(), normal.y(), normal.z()) + ", offset = " + num(offset) +
         " } } ]\n";
}

inline core::CaseSpec case_of(const std::string& toml) {
  return io::case_from_toml(toml, std::string(TT_BINARY_DIR) + "/thermal_verification.toml");
}

/// A mesh and what the solver made of it.
struct Solution {
  mesh::TetMesh mesh;
  solvers::ThermalHistory history;
};

inline Solution run_case(const core::CaseSpec& spec, const mesh::TetMesh& mesh) {
  const auto ops = solvers::thermal_system(mesh, spec);
  return {mesh, solvers::thermal_history(mesh, spec, ops)};
}

inline Solution run_case(const core::CaseSpec& spec) {
  return run_case(spec, mesh::mesh_case(spec));
}

/// Column of `times` equal to t (to 1e-9 s); fails the test when absent.
inline int time_column(const std::vector<double>& times, double t) {
  for (size_t i = 0; i < times.size(); ++i)
    if (std::abs(times[i] - t) < 1e-9) return static_cast<int>(i);
  ADD_FAILURE() << "no output at t = " << t << " s";
  return 0;
}

/// Temperature [degC] of named point `id` at output time t [s].
inline double celsius_at(const Solution& run, const std::string& id, double t) {
  const int node = mesh::named_node(run.mesh, id);
  EXPECT_GE(node, 0) << "no named point " << id;
  return run.history.temperature(node, time_column(run.history.times, t)) - core::kCelsiusOffset;
}

/// Roots of zeta tan(zeta) = Bi, one in each (n pi, n pi + pi/2), by bisection.
inline std::vector<double> slab_eigenvalues(double biot, int count) {
  std::vector<double> z;
  for (int n = 0; n < count; ++n) {
    double a = n * kPi, b = n * kPi + 0.5 * kPi - 1e-14;
    for (int it = 0; it < 200; ++it) {
      const double m = 0.5 * (a + b);
      (m * std::tan(m) - biot < 0 ? a : b) = m;
    }
    z.push_back(0.5 * (a + b));
  }
  return z;
}

/// (T - T_inf) / (T_i - T_inf) in a slab insulated at x = 0 with convection at x = L:
/// sum C_n exp(-zeta_n^2 Fo) cos(zeta_n x / L), C_n = 4 sin zeta_n / (2 zeta_n + sin 2 zeta_n).
inline double slab_theta(double x_over_l, double fourier, double biot, int terms = 200) {
  double sum = 0;
  for (double z : slab_eigenvalues(biot, terms))
    sum += 4 * std::sin(z) / (2 * z + std::sin(2 * z)) * std::exp(-z * z * fourier) *
           std::cos(z * x_over_l);
  return sum;
}

/// Observed order of convergence between two (size, error) pairs.
inline double observed_order(double h1, double e1, double h2, double e2) {
  return std::log(e1 / e2) / std::log(h1 / h2);
}

}  // namespace tt::thermal_test
