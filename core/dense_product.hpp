// The product of two dense matrices, by the method that is faster for their size. Eigen's blocked
// GEMM is OpenMP-parallel; on the shared 2-core machine its threads wait on each other, and for
// matrices of ~100 rows the coefficient-wise lazyProduct was as fast or faster (0.11 against 0.11
// ms at 91 rows, 0.22 against 0.71 ms at 128 rows, with 2 threads). From about 192 rows on the
// blocked product is 3 to 9 times faster with 1 or 2 threads (0.25 / 0.29 against 0.81 ms at
// 192 rows, 6.6 / 3.8 against 57 ms at 590 rows): the observer's covariance on a twin of several
// hundred states (GM-1's) spends nearly all its time in such products. Measured 2026-11-26 on the
// 2-core VM (g++ 12 -O3 -march=native, Eigen 3.4).
#pragma once

#include <Eigen/Core>

namespace tt::core {

/// Work (rows x inner x columns) from which dense_product takes the blocked product: 192^3.
inline constexpr double kBlockedProductWork = 192.0 * 192.0 * 192.0;

/// a b as a plain matrix: Eigen's blocked product for work from kBlockedProductWork on, the
/// coefficient-wise one below it.
template <class A, class B>
Eigen::MatrixXd dense_product(const A& a, const B& b) {
  const double work =
      static_cast<double>(a.rows()) * static_cast<double>(a.cols()) * static_cast<double>(b.cols());
  if (work >= kBlockedProductWork) {
    Eigen::MatrixXd out(a.rows(), b.cols());
    out.noalias() = a * b;
    return out;
  }
  return a.lazyProduct(b);
}

}  // namespace tt::core
