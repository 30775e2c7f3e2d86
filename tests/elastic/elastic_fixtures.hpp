// Shared pieces of the elastic verification tests: small box-body cases written as TOML and read
// through the case reader (so the tests exercise the same path as a real run), temperature fields
// built directly on the mesh nodes, and the exact solutions' rigid-motion part fixed by the
// supports.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <functional>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/elastic.hpp"
#include "solvers/thermal.hpp"

namespace tt::elastic_test {

struct MaterialText {
  std::string name;
  double youngs_modulus;  /// [Pa]
  double poisson_ratio;   /// [-]
  double expansion;       /// [1/K]
};

struct BoxText {
  std::string name, material;
  Eigen::Vector3d min, max;  /// [m]
  double max_edge;           /// [m]
};

struct PointText {
  std::string id;
  Eigen::Vector3d position;  /// [m]
};

/// A case of box bodies; `boundary` and `mechanical` are TOML fragments written verbatim
/// ([[boundary]] tables, and the body of the [mechanical] table).
struct BoxCase {
  std::vector<MaterialText> materials;
  std::vector<BoxText> bodies;
  std::vector<PointText> points;
  std::string boundary;
  std::string mechanical;
  int order = 2;
  double reference_temperature_c = 20.0;
};

inline std::string vec_text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << std::setprecision(17) << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return s.str();
}

/// The case as TOML; every thermal setting is a placeholder the elastic solver never reads.
inline std::string case_text(const BoxCase& c) {
  std::ostringstream s;
  s << std::setprecision(17);
  s << "[case]\nname = \"elastic verification\"\n\n[geometry]\nlength_unit = \"m\"\n\n";
  for (const auto& m : c.materials)
    s << "[materials." << m.name << "]\ndensity_kg_m3 = 7800.0\nspecific_heat_J_kgK = 460.0\n"
      << "conductivity_W_mK = 40.0\nyoungs_modulus_Pa = " << m.youngs_modulus
      << "\npoisson_ratio = " << m.poisson_ratio << "\nexpansion_per_K = " << m.expansion << "\n\n";
  for (const auto& b : c.bodies)
    s << "[[bodies]]\nname = \"" << b.name << "\"\nmaterial = \"" << b.material
      << "\"\nmax_edge = " << b.max_edge << "\nadd = [ { box = { min = " << vec_text(b.min)
      << ", max = " << vec_text(b.max) << " } } ]\n\n";
  s << "[mesh]\norder = " << c.order << "\n\n" << c.boundary << "\n";
  s << "[duty_cycle]\nend_s = 100.0\nsegments = [ { start_s = 0.0, speed_rpm = 0.0 } ]\n\n";
  s << "[mechanical]\nreference_temperature_degC = " << c.reference_temperature_c << "\n"
    << c.mechanical << "\n\n";
  if (!c.points.empty()) {
    s << "[points]\nlist = [\n";
    for (const auto& p : c.points)
      s << "  { id = \"" << p.id << "\", position = " << vec_text(p.position) << " },\n";
    s << "]\n";
  }
  return s.str();
}

inline core::CaseSpec spec_of(const BoxCase& c) {
  return io::case_from_toml(case_text(c), "elastic_verification.toml");
}

/// #nodes temperatures [K] of a field given in degC at a position [m].
inline Eigen::VectorXd nodal_temperature_k(
    const mesh::TetMesh& mesh, const std::function<double(const Eigen::Vector3d&)>& t_c) {
  Eigen::VectorXd t(mesh.nodes.rows());
  for (Eigen::Index i = 0; i < t.size(); ++i)
    t(i) = t_c(mesh.nodes.row(i).transpose()) + core::kCelsiusOffset;
  return t;
}

using Field = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;

/// The exact displacement [m] from a particular solution `u_p` plus the rigid motion t + w x x
/// that zeroes it at every held dof (least squares over the held dofs; exact when the supports
/// hold only rigid motions). Returns 3 #nodes, node-major.
inline Eigen::VectorXd exact_with_supports(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                           const Field& u_p) {
  const std::vector<char> held = solvers::constrained_dofs(mesh, spec);
  std::vector<Eigen::Matrix<double, 1, 6>> rows;
  std::vector<double> rhs;
  for (Eigen::Index i = 0; i < mesh.nodes.rows(); ++i) {
    const Eigen::Vector3d x = mesh.nodes.row(i).transpose();
    const Eigen::Vector3d u = u_p(x);
    for (int d = 0; d < 3; ++d) {
      if (!held[3 * i + d]) continue;
      Eigen::Matrix<double, 1, 6> row = Eigen::Matrix<double, 1, 6>::Zero();
      row(d) = 1.0;
      for (int a = 0; a < 3; ++a)
        row(3 + a) = Eigen::Vector3d::Unit(a).cross(x)(d);  // d-component of (e_a x x)
      rows.push_back(row);
      rhs.push_back(-u(d));
    }
  }
  Eigen::MatrixXd a(static_cast<Eigen::Index>(rows.size()), 6);
  Eigen::VectorXd b(static_cast<Eigen::Index>(rows.size()));
  for (size_t r = 0; r < rows.size(); ++r) {
    a.row(static_cast<Eigen::Index>(r)) = rows[r];
    b(static_cast<Eigen::Index>(r)) = rhs[r];
  }
  const Eigen::Matrix<double, 6, 1> rigid = a.colPivHouseholderQr().solve(b);
  Eigen::VectorXd u(3 * mesh.nodes.rows());
  for (Eigen::Index i = 0; i < mesh.nodes.rows(); ++i) {
    const Eigen::Vector3d x = mesh.nodes.row(i).transpose();
    u.segment<3>(3 * i) = u_p(x) + rigid.head<3>() + rigid.tail<3>().cross(x);
  }
  return u;
}

/// max_i |u_i - v_i| over all nodal components, relative to max |v|.
inline double max_relative_error(const Eigen::VectorXd& u, const Eigen::VectorXd& exact) {
  return (u - exact).lpNorm<Eigen::Infinity>() / exact.lpNorm<Eigen::Infinity>();
}

}  // namespace tt::elastic_test
