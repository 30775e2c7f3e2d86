// Linear thermo-elasticity on the thermal mesh: the stiffness is factored once and every output
// time is solved as one multi-right-hand-side block.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <utility>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"

namespace tt::solvers {

struct ElasticTimings {
  double assemble_s = 0, factor_s = 0, solve_s = 0;
  int dofs = 0, free_dofs = 0;
};

struct ElasticHistory {
  Eigen::MatrixXd displacement;  /// 3 #nodes x #times, node-major (x, y, z) [m]
  ElasticTimings timings;
};

/// Dofs held by the case: every dof of nodes on fixed groups, and the point supports' dofs.
/// Throws SolverError when the constraints leave a rigid motion free.
std::vector<char> constrained_dofs(const mesh::TetMesh& mesh, const core::CaseSpec& spec);

/// The factored stiffness of a case and its thermal coupling: built once, then displacements for
/// any temperature fields, or influence vectors that make one displacement component a dot
/// product with the temperature field (the adjoint route for a few points).
class ElasticModel {
 public:
  ElasticModel(const mesh::TetMesh& mesh, const core::CaseSpec& spec);
  ~ElasticModel();
  ElasticModel(ElasticModel&&) noexcept;

  /// 3 #nodes x #times displacements [m] for temperature fields #nodes x #times [K].
  Eigen::MatrixXd displacements(const Eigen::MatrixXd& temperature) const;
  /// a with u(node, direction) = a . (T - T_ref) for every temperature field T [m/K].
  Eigen::VectorXd influence(int node, int direction) const;
  /// Influence rows of displacement functionals: row i is a_i with f_i . u = a_i . (T - T_ref),
  /// f = `functionals` (#rows x 3 #nodes, node-major x, y, z) [m/K]; one block solve.
  Eigen::MatrixXd influence_rows(const Eigen::SparseMatrix<double>& functionals) const;
  /// influence(node, direction) of each (node, direction) pair, as rows, in one block solve.
  Eigen::MatrixXd influence_rows(const std::vector<std::pair<int, int>>& node_directions) const;
  /// The same rows split by material: entry m is the part of influence_rows that the thermal
  /// strain of material m's elements makes, so that a change of material m's expansion
  /// coefficient by a factor (1 + x) adds x times it (the stiffness does not depend on the
  /// expansion). `mesh` and `spec` must be the model's. Entries sum to influence_rows.
  std::vector<Eigen::MatrixXd> influence_rows_by_material(
      const Eigen::SparseMatrix<double>& functionals, const mesh::TetMesh& mesh,
      const core::CaseSpec& spec) const;
  /// influence_rows and influence_rows_by_material from one block solve.
  struct SplitRows {
    Eigen::MatrixXd rows;                      /// influence_rows
    std::vector<Eigen::MatrixXd> by_material;  /// influence_rows_by_material
  };
  SplitRows influence_rows_split(const std::vector<std::pair<int, int>>& node_directions,
                                 const mesh::TetMesh& mesh, const core::CaseSpec& spec) const;
  double reference_temperature_k() const { return reference_k_; }
  const ElasticTimings& timings() const { return timings_; }

 private:
  struct Impl;
  /// K^-1 f^T on the free dofs, scattered to all dofs (held ones 0): 3 #nodes x #rows.
  Eigen::MatrixXd adjoint_solutions(const Eigen::SparseMatrix<double>& functionals) const;
  /// The unit functionals of (node, direction) pairs: #pairs x 3 #nodes; SolverError when a
  /// node or direction is out of range.
  Eigen::SparseMatrix<double> unit_functionals(
      const std::vector<std::pair<int, int>>& node_directions) const;
  /// rows_by_material on the adjoint solutions w, the mesh checked to be the model's.
  std::vector<Eigen::MatrixXd> split_by_material(const Eigen::MatrixXd& w,
                                                 const mesh::TetMesh& mesh,
                                                 const core::CaseSpec& spec) const;
  std::unique_ptr<Impl> impl_;
  double reference_k_ = 0;
  ElasticTimings timings_;
};

/// Displacements for each column of `temperature` (#nodes x #times [K]).
ElasticHistory elastic_history(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                               const Eigen::MatrixXd& temperature);

/// Von Mises stress per node [Pa] (element nodal stresses averaged at each node).
Eigen::VectorXd von_mises_nodal(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                                const Eigen::VectorXd& displacement,
                                const Eigen::VectorXd& temperature);

/// Displacement [m] at a point inside the mesh (interpolated in the element that contains it).
Eigen::Vector3d displacement_at(const mesh::TetMesh& mesh, const Eigen::VectorXd& displacement,
                                const Eigen::Vector3d& point);

}  // namespace tt::solvers
