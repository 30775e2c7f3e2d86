// Sparse Cholesky factor of a symmetric positive definite matrix through CHOLMOD (supernodal,
// with the system's BLAS). CHOLMOD's status and `minor` become SolverError with context.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>

namespace tt::solvers::cholmod {

/// Pins the BLAS behind CHOLMOD to `threads` threads (OpenBLAS; no effect on other BLAS).
/// One thread is the default of the CLI: bitwise-repeatable results and, for the per-step
/// back-substitutions of this size, faster than two.
void set_blas_threads(int threads);

/// The fill-reducing ordering and symbolic factor of a sparsity pattern, computed once and shared
/// (read only, so from several threads) by the factors of matrices with that pattern, such as the
/// shifted operators K(h) + s C of a reduced basis.
/// The OpenBLAS core type that matches this CPU when the loaded OpenBLAS chose a slower one, else
/// empty. Debian's OpenBLAS picks its kernels from the CPU model when it is loaded; a CPU it does
/// not know (a virtual machine that reports a generic model) gets Prescott's SSE3 kernels even
/// when it has AVX-512 or AVX2, and the sparse factors' dense blocks run slower. OpenBLAS takes
/// the choice from OPENBLAS_CORETYPE only when it is loaded, so the caller must start again with
/// it set (app/main.cpp does).
std::string better_blas_core();

class Analysis {
 public:
  /// Analyses A's pattern (column-major, compressed; upper triangle). `what` names it in errors.
  Analysis(const Eigen::SparseMatrix<double>& a, std::string what);
  ~Analysis();
  Analysis(const Analysis&) = delete;
  Analysis& operator=(const Analysis&) = delete;

 private:
  friend class Factor;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class Factor {
 public:
  /// Factors A (column-major, compressed; only its upper triangle is read). `what` names the
  /// matrix in error messages.
  Factor(const Eigen::SparseMatrix<double>& a, std::string what);
  /// Factors A, whose pattern is the analysed one, without analysing it again. Throws
  /// SolverError when A has another size or number of entries.
  Factor(const Analysis& analysis, const Eigen::SparseMatrix<double>& a, std::string what);
  ~Factor();
  Factor(const Factor&) = delete;
  Factor& operator=(const Factor&) = delete;

  /// x with A x = b; b may have several columns.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;
  /// In-place single right-hand side, reusing workspace (the per-step path).
  void solve_in_place(Eigen::VectorXd& x) const;

  /// Stored entries of the factor L (for the memory-bandwidth bound).
  double factor_entries() const;
  int rows() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  void factorize(const Eigen::SparseMatrix<double>& a);
};

}  // namespace tt::solvers::cholmod
