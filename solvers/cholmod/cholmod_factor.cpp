#include "solvers/cholmod/cholmod_factor.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "core/errors.hpp"

extern "C" void openblas_set_num_threads(int) __attribute__((weak));
extern "C" char* openblas_get_corename() __attribute__((weak));

namespace tt::solvers::cholmod {

void set_blas_threads(int threads) {
  if (openblas_set_num_threads) openblas_set_num_threads(threads);
}

std::string better_blas_core() {
  if (!openblas_get_corename) return {};  // another BLAS
  const std::string chosen = openblas_get_corename();
  if (chosen != "Prescott" && chosen != "prescott") return {};
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) return "SkylakeX";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "Haswell";
  return {};
}

struct Factor::Impl {
  cholmod_common common;
  cholmod_factor* factor = nullptr;
  // Workspace for cholmod_solve2 so that a step allocates nothing.
  mutable cholmod_dense* x = nullptr;
  mutable cholmod_dense* y = nullptr;
  mutable cholmod_dense* e = nullptr;
  mutable cholmod_dense* b = nullptr;
  int n = 0;
  std::string what;

  Impl() { cholmod_start(&common); }
  ~Impl() {
    cholmod_free_dense(&x, &common);
    cholmod_free_dense(&y, &common);
    cholmod_free_dense(&e, &common);
    cholmod_free_dense(&b, &common);
    if (factor) cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
  }
};

namespace {

/// A view of an Eigen column-major compressed matrix as cholmod_sparse, without copying.
cholmod_sparse view_of(const Eigen::SparseMatrix<double>& a) {
  cholmod_sparse s;
  std::memset(&s, 0, sizeof(s));
  s.nrow = static_cast<size_t>(a.rows());
  s.ncol = static_cast<size_t>(a.cols());
  s.nzmax = static_cast<size_t>(a.nonZeros());
  s.p = const_cast<int*>(a.outerIndexPtr());
  s.i = const_cast<int*>(a.innerIndexPtr());
  s.x = const_cast<double*>(a.valuePtr());
  s.stype = 1;  // symmetric, upper triangle used
  s.itype = CHOLMOD_INT;
  s.xtype = CHOLMOD_REAL;
  s.dtype = CHOLMOD_DOUBLE;
  s.sorted = 1;
  s.packed = 1;
  return s;
}

cholmod_dense dense_view(double* data, int rows, int cols) {
  cholmod_dense d;
  std::memset(&d, 0, sizeof(d));
  d.nrow = static_cast<size_t>(rows);
  d.ncol = static_cast<size_t>(cols);
  d.nzmax = d.nrow * d.ncol;
  d.d = d.nrow;
  d.x = data;
  d.xtype = CHOLMOD_REAL;
  d.dtype = CHOLMOD_DOUBLE;
  return d;
}

}  // namespace

namespace {

void check_square(const Eigen::SparseMatrix<double>& a, const std::string& what) {
  if (a.rows() != a.cols() || !a.isCompressed())
    throw core::SolverError(what + ": matrix must be square and compressed");
}

cholmod_factor* analysed(const Eigen::SparseMatrix<double>& a, cholmod_common& c,
                         const std::string& what) {
  cholmod_sparse s = view_of(a);
  c.supernodal = CHOLMOD_SUPERNODAL;
  cholmod_factor* f = cholmod_analyze(&s, &c);
  if (!f || c.status < CHOLMOD_OK)
    throw core::SolverError(what + ": CHOLMOD analysis failed (status " + std::to_string(c.status) +
                            ")");
  return f;
}

}  // namespace

struct Analysis::Impl {
  cholmod_common common;
  cholmod_factor* symbolic = nullptr;
  std::vector<int> outer, inner;  // the analysed pattern, to refuse another
  Impl() { cholmod_start(&common); }
  ~Impl() {
    if (symbolic) cholmod_free_factor(&symbolic, &common);
    cholmod_finish(&common);
  }
};

Analysis::Analysis(const Eigen::SparseMatrix<double>& a, std::string what)
    : impl_(std::make_unique<Impl>()) {
  check_square(a, what);
  impl_->outer.assign(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1);
  impl_->inner.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
  impl_->symbolic = analysed(a, impl_->common, what);
}

Analysis::~Analysis() = default;

Factor::Factor(const Eigen::SparseMatrix<double>& a, std::string what)
    : impl_(std::make_unique<Impl>()) {
  impl_->what = std::move(what);
  check_square(a, impl_->what);
  impl_->n = static_cast<int>(a.rows());
  impl_->factor = analysed(a, impl_->common, impl_->what);
  factorize(a);
}

Factor::Factor(const Analysis& analysis, const Eigen::SparseMatrix<double>& a, std::string what)
    : impl_(std::make_unique<Impl>()) {
  impl_->what = std::move(what);
  check_square(a, impl_->what);
  const auto& p = *analysis.impl_;
  const bool same = a.outerSize() + 1 == static_cast<Eigen::Index>(p.outer.size()) &&
                    a.nonZeros() == static_cast<Eigen::Index>(p.inner.size()) &&
                    std::equal(p.outer.begin(), p.outer.end(), a.outerIndexPtr()) &&
                    std::equal(p.inner.begin(), p.inner.end(), a.innerIndexPtr());
  if (!same)
    throw core::SolverError(impl_->what + ": its pattern (" + std::to_string(a.rows()) + " rows, " +
                            std::to_string(a.nonZeros()) + " entries) is not the analysed one (" +
                            std::to_string(p.outer.size() - 1) + " rows, " +
                            std::to_string(p.inner.size()) + " entries)");
  impl_->n = static_cast<int>(a.rows());
  impl_->common.supernodal = CHOLMOD_SUPERNODAL;
  impl_->factor = cholmod_copy_factor(analysis.impl_->symbolic, &impl_->common);
  if (!impl_->factor)
    throw core::SolverError(impl_->what + ": CHOLMOD could not copy the analysis (status " +
                            std::to_string(impl_->common.status) + ")");
  factorize(a);
}

void Factor::factorize(const Eigen::SparseMatrix<double>& a) {
  cholmod_sparse s = view_of(a);
  cholmod_common& c = impl_->common;
  cholmod_factorize(&s, impl_->factor, &c);
  if (c.status == CHOLMOD_NOT_POSDEF || impl_->factor->minor < impl_->factor->n)
    throw core::SolverError(
        impl_->what + ": matrix is not positive definite (CHOLMOD stopped at column " +
        std::to_string(impl_->factor->minor) + " of " + std::to_string(impl_->n) +
        "). Hint: a body may be unconstrained (rigid motion) or have zero conductivity/stiffness.");
  if (c.status < CHOLMOD_OK)
    throw core::SolverError(impl_->what + ": CHOLMOD factorisation failed (status " +
                            std::to_string(c.status) + ")");
}

Factor::~Factor() = default;

Eigen::MatrixXd Factor::solve(const Eigen::MatrixXd& b) const {
  if (b.rows() != impl_->n)
    throw core::SolverError(impl_->what + ": right-hand side has " + std::to_string(b.rows()) +
                            " rows, expected " + std::to_string(impl_->n));
  Eigen::MatrixXd copy = b;
  cholmod_dense bd =
      dense_view(copy.data(), static_cast<int>(b.rows()), static_cast<int>(b.cols()));
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, impl_->factor, &bd, &impl_->common);
  if (!x) throw core::SolverError(impl_->what + ": CHOLMOD solve failed");
  Eigen::MatrixXd result =
      Eigen::Map<Eigen::MatrixXd>(static_cast<double*>(x->x), b.rows(), b.cols());
  cholmod_free_dense(&x, &impl_->common);
  return result;
}

void Factor::solve_in_place(Eigen::VectorXd& v) const {
  cholmod_dense bd = dense_view(v.data(), impl_->n, 1);
  Impl& m = *impl_;
  if (!cholmod_solve2(CHOLMOD_A, m.factor, &bd, nullptr, &m.x, nullptr, &m.y, &m.e, &m.common))
    throw core::SolverError(m.what + ": CHOLMOD solve failed");
  std::memcpy(v.data(), m.x->x, sizeof(double) * static_cast<size_t>(m.n));
}

double Factor::factor_entries() const {
  const cholmod_factor* f = impl_->factor;
  if (f->is_super) {
    // Supernodal: the stored block columns.
    return static_cast<double>(f->xsize);
  }
  return static_cast<double>(f->nzmax);
}

int Factor::rows() const {
  return impl_->n;
}

}  // namespace tt::solvers::cholmod
