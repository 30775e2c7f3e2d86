// Heat that travels with a feed axis: a ball-screw nut or a carriage's guide blocks heat only the
// part of the screw (rails) under them. The matrix does not change as the axis moves, only the
// load: per step, the heat is spread over the tets whose centroid lies in the window around the
// axis position, averaged over the positions the axis passes through during the step, with the
// total power exact at every instant.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"

namespace tt::solvers {

/// One moving source's body, cut into its tets sorted along the axis.
struct MovingSourceShape {
  int source = -1;         /// index into spec.thermal.sources
  Eigen::VectorXd centre;  /// #pieces tet centroid coordinate along the axis, ascending [m]
  Eigen::VectorXd volume;  /// #pieces tet volume [m^3]
  Eigen::MatrixXi nodes;   /// #pieces x nodes-per-tet mesh nodes
  Eigen::MatrixXd weight;  /// #pieces x nodes-per-tet int N dV [m^3] (rows sum to volume)
};

/// The shapes of every source with a window (moving with spec.feed_axis). Throws SolverError for
/// a moving source on a body without elements.
std::vector<MovingSourceShape> moving_source_shapes(const mesh::TetMesh& mesh,
                                                    const core::CaseSpec& spec);

/// Nodal load of the source per watt in each piece: #nodes x #pieces, column p spreads piece p's
/// unit power over its nodes by int N dV / V_piece (each column sums to 1) [-].
Eigen::SparseMatrix<double> moving_load_matrix(const MovingSourceShape& shape, Eigen::Index nodes);

/// The window at one of a step's sub-instants: pieces [lo, hi) share the power by volume, each
/// piece p receiving volume_p * per_volume of it (per_volume = 1 / (sub-instants x their volume)).
struct WindowShare {
  Eigen::Index lo = 0, hi = 0;
  double per_volume = 0;  /// [1/m^3]
};

/// The windows of the step [t0, t1]: enough sub-instants that the window moves at most an eighth
/// of its length between two; the piece nearest the window's centre takes it all when the window
/// holds no centroid.
std::vector<WindowShare> moving_windows(const core::CaseSpec& spec, const MovingSourceShape& shape,
                                        double t0, double t1);

/// Per piece, the fraction of the source's power it receives averaged over [t0, t1] [-] (sums to
/// 1): the windows' shares summed per piece.
Eigen::VectorXd moving_piece_fractions(const core::CaseSpec& spec, const MovingSourceShape& shape,
                                       double t0, double t1);

/// Prefix sums along the pieces of the volume-weighted load columns, #space x (#pieces + 1):
/// column i = sum over p < i of volume_p load.col(p). A window's load per watt is then
/// per_volume (prefix.col(hi) - prefix.col(lo)): one column difference per sub-instant instead of
/// one column per piece (a reduced system's load matrix is dense). Throws SolverError when load
/// has not one column per piece.
Eigen::MatrixXd moving_prefix(const Eigen::MatrixXd& load, const MovingSourceShape& shape);

}  // namespace tt::solvers
