// Dense products of tall matrices (one row per node, a few hundred to a thousand columns), as the
// reduced basis is built and projected: the rows in fixed chunks, the chunks side by side.
//
// Why not Eigen's own threaded product: for a tall a^T b (a small result over a deep sum) it splits
// the result, not the sum, and synchronises the threads per block; measured on the shared 2-core
// machine under load (docs/reduced-order.md), it ran 4 times slower than one thread, and 100 to
// 300 times slower for a 100 x 16 result. Each chunk here is one single-threaded product, and the
// chunks do not depend on the thread count, so neither do the bits of the result.
#pragma once

#include <Eigen/Core>

namespace tt::solvers {

/// a^T b for a (#rows x p) and b (#rows x q) with the same rows: p x q, the chunks' partial
/// products summed in chunk order. Throws SolverError when the row counts differ.
Eigen::MatrixXd tall_transposed_product(const Eigen::Ref<const Eigen::MatrixXd>& a,
                                        const Eigen::Ref<const Eigen::MatrixXd>& b);

/// x -= a c, for a (#rows x p), c (p x q) and x (#rows x q). Throws SolverError when the sizes
/// do not fit.
void subtract_tall_product(Eigen::Ref<Eigen::MatrixXd> x,
                           const Eigen::Ref<const Eigen::MatrixXd>& a,
                           const Eigen::Ref<const Eigen::MatrixXd>& c);

/// v^T w when the result is known to be symmetric (w = A v, A symmetric): only the blocks on and
/// below the diagonal are formed (half the products), then mirrored. r x r for v, w #rows x r.
Eigen::MatrixXd symmetric_tall_product(const Eigen::Ref<const Eigen::MatrixXd>& v,
                                       const Eigen::Ref<const Eigen::MatrixXd>& w);

}  // namespace tt::solvers
