#include "solvers/cholmod/cholmod_factor.hpp"

#include <cholmod.h>

#include <cstring>

#include "core/errors.hpp"

extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace tt::solvers::cholmod {

void set_blas_threads(int threads) {
  if (openblas_set_num_threads) openblas_set_num_threads(threads);
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

Factor::Factor(const Eigen::SparseMatrix<double>& a, std::string what) : impl_(std::make_unique<Impl>()) {
  impl_->what = std::move(what);
  if (a.rows() != a.cols() || !a.isCompressed())
    throw core::SolverError(impl_->what + ": matrix must be square and compressed");
  impl_->n = static_cast<int>(a.rows());
  cholmod_sparse s = view_of(a);
  cholmod_common& c = impl_->common;
  c.supernodal = CHOLMOD_SUPERNODAL;
  impl_->factor = cholmod_analyze(&s, &c);
  if (!impl_->factor || c.status < CHOLMOD_OK)
    throw core::SolverError(impl_->what + ": CHOLMOD analysis failed (status " +
                            std::to_string(c.status) + ")");
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
  cholmod_dense bd = dense_view(copy.data(), static_cast<int>(b.rows()), static_cast<int>(b.cols()));
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, impl_->factor, &bd, &impl_->common);
  if (!x) throw core::SolverError(impl_->what + ": CHOLMOD solve failed");
  Eigen::MatrixXd result = Eigen::Map<Eigen::MatrixXd>(static_cast<double*>(x->x), b.rows(), b.cols());
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

int Factor::rows() const { return impl_->n; }

}  // namespace tt::solvers::cholmod
