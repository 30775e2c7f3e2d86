// The linear thermal system of a case, independent of time and speed: one description that the
// full model (assembled from the mesh) and a reduced one (projected on a basis) share, so that
// one time stepper steps both.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/feed_axis.hpp"

namespace tt::solvers {

/// C dT/dt + (K + sum_c h_c(t) F_c) T = sum of input columns times their scalar inputs.
/// The same struct holds the full model (Matrix = Eigen::SparseMatrix<double>, vectors of #nodes)
/// and a reduced one (Matrix = Eigen::MatrixXd, vectors of #states, T = V z).
template <class Matrix>
struct LinearThermalSystem {
  Matrix capacity;                         /// C [J/K]
  Matrix conduction;                       /// K [W/K]
  std::vector<Matrix> film;                /// per convection entry: int N N^T dA [m^2]
  std::vector<Eigen::VectorXd> film_area;  /// per convection entry: int N dA [m^2]
  std::vector<Eigen::VectorXd>
      source_shape;  /// per heat source: unit-power load [-] (sums to 1 in full)
  std::vector<Eigen::VectorXd> flux_area;  /// per surface flux: int N dA [m^2]
  std::vector<Matrix> moving;              /// per moving source (index into spec sources kept
                                           /// in moving_source): #space x #pieces, column p =
                                           /// piece p's nodal load per watt [-]
  std::vector<int> moving_source;          /// per moving entry: index into spec.thermal.sources
  Eigen::VectorXd uniform;                 /// the state of a uniform 1 K field (ones in full)
  /// Per moving entry: its pieces along the axis (centroids, volumes; the full mesh's nodes and
  /// weights), from which solvers/feed_axis computes each piece's share of the power over a step.
  /// Independent of the space: a reduced system keeps the full one's.
  std::vector<MovingSourceShape> moving_pieces;
  /// A reduced system only: per moving entry, moving_prefix(moving[k], moving_pieces[k]), from
  /// which the stepper forms a step's moving load in one column difference per sub-instant
  /// (projected_system and the reduced-model reader fill it; with_moving_prefix adds it).
  std::vector<Eigen::MatrixXd> moving_prefix;

  Eigen::Index states() const { return capacity.rows(); }
};
using FullThermalSystem = LinearThermalSystem<Eigen::SparseMatrix<double>>;
using ReducedThermalSystem = LinearThermalSystem<Eigen::MatrixXd>;

/// `reduced` with its moving_prefix filled.
LinearThermalSystem<Eigen::MatrixXd> with_moving_prefix(
    LinearThermalSystem<Eigen::MatrixXd> reduced);

/// The full system of `spec` on `mesh` (element loops in parallel, deterministic order). Throws
/// SolverError for inverted elements and sources on empty bodies.
FullThermalSystem thermal_system(const mesh::TetMesh& mesh, const core::CaseSpec& spec);

}  // namespace tt::solvers
