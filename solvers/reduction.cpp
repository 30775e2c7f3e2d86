#include "solvers/reduction.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>

#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "solvers/cholmod/cholmod_factor.hpp"
#include "solvers/loads.hpp"
#include "solvers/tall_products.hpp"

namespace tt::solvers {
namespace {

using Sparse = Eigen::SparseMatrix<double>;
using Clock = std::chrono::steady_clock;

/// K(h) = K + sum_c h_c F_c [W/K].
Sparse film_stiffness(const FullThermalSystem& full, const std::vector<double>& h) {
  Sparse k = full.conduction;
  for (size_t c = 0; c < h.size(); ++c) k += h[c] * full.film[c];
  k.makeCompressed();
  return k;
}

/// Whether some film removes heat under h, so that K(h) is positive definite (s = 0 allowed).
bool removes_heat(const FullThermalSystem& full, const std::vector<double>& h) {
  for (size_t c = 0; c < h.size(); ++c)
    if (h[c] > 0 && full.film_area[c].sum() > 0) return true;
  return false;
}

void check_options(const ReductionOptions& o) {
  const auto fail = [](const std::string& what) {
    throw core::SolverError("reduction options: " + what);
  };
  for (double s : o.shifts_per_s)
    if (!(s >= 0) || !std::isfinite(s))
      fail("shift " + std::to_string(s) + " 1/s: must be finite and >= 0");
  for (double n : o.speeds_rpm)
    if (!(n >= 0) || !std::isfinite(n))
      fail("speed " + std::to_string(n) + " rpm: must be finite and >= 0");
  if (!(o.deflation_tolerance > 0 && o.deflation_tolerance < 1))
    fail("deflation_tolerance = " + std::to_string(o.deflation_tolerance) + ": must be in (0, 1)");
  if (!(o.compression_tolerance >= 0 && o.compression_tolerance < 1))
    fail("compression_tolerance = " + std::to_string(o.compression_tolerance) +
         ": must be in [0, 1)");
  if (!(o.moving_slice_fraction > 0 && o.moving_slice_fraction <= 1))
    fail("moving_slice_fraction = " + std::to_string(o.moving_slice_fraction) +
         ": must be in (0, 1]");
}

/// Per film state, h per convection entry at each speed asked for (duplicates once).
std::vector<std::vector<double>> film_states(const core::CaseSpec& spec,
                                             const ReductionOptions& o) {
  std::vector<double> speeds = o.speeds_rpm;
  if (speeds.empty()) {
    double top = 0;
    for (const auto& seg : spec.duty_cycle.segments) top = std::max(top, seg.speed_rpm);
    speeds = {0.0, top};
  }
  std::vector<std::vector<double>> states;
  for (double n : speeds) {
    std::vector<double> h;
    for (const auto& c : spec.thermal.convection) h.push_back(film_coefficient(c, n));
    if (std::find(states.begin(), states.end(), h) == states.end()) states.push_back(h);
  }
  return states;
}

/// 0 (when allowed) and five shifts log-spaced from 1/(10 h) to 1/step [1/s].
std::vector<double> default_shifts(const core::CaseSpec& spec, bool steady) {
  std::vector<double> s;
  if (steady) s.push_back(0.0);
  const double lo = 1.0 / 36000.0, hi = 1.0 / std::max(spec.thermal.step, 1e-3);
  constexpr int count = 5;
  for (int i = 0; i < count; ++i) s.push_back(lo * std::pow(hi / lo, i / double(count - 1)));
  return s;
}

/// The pieces of a moving source grouped into slices of width `width` along the axis: per
/// slice, weights over the pieces (their volumes, summing to 1): #pieces x #slices.
Eigen::MatrixXd slice_weights(const MovingSourceShape& shape, double width) {
  const Eigen::Index n = shape.centre.size();
  std::vector<Eigen::VectorXd> slices;
  Eigen::Index i = 0;
  while (i < n) {
    const double start = shape.centre(i);
    Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
    for (; i < n && shape.centre(i) < start + width; ++i) w(i) = shape.volume(i);
    slices.push_back(w / w.sum());
  }
  Eigen::MatrixXd out(n, static_cast<Eigen::Index>(slices.size()));
  for (size_t j = 0; j < slices.size(); ++j) out.col(static_cast<Eigen::Index>(j)) = slices[j];
  return out;
}

/// The pieces of a moving source weighted by hats along the axis, centres equally spaced at most
/// `spacing` apart from the first piece's centre to the last's: per hat, weights over the pieces
/// (volume times the hat at the piece's centre, summing to 1): #pieces x #hats. A power density
/// that is linear between the hats' centres is in their span, where slices hold constant ones.
Eigen::MatrixXd hat_weights(const MovingSourceShape& shape, double spacing) {
  const Eigen::Index n = shape.centre.size();
  const double lo = shape.centre(0), length = shape.centre(n - 1) - lo;
  const Eigen::Index intervals =
      std::max<Eigen::Index>(1, static_cast<Eigen::Index>(std::ceil(length / spacing - 1e-9)));
  const double h = length / static_cast<double>(intervals);
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(n, intervals + 1);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(h > 0)) {
      w(i, 0) = shape.volume(i);
      continue;
    }
    const double x = (shape.centre(i) - lo) / h;
    const Eigen::Index j = std::clamp<Eigen::Index>(static_cast<Eigen::Index>(x), 0, intervals - 1);
    const double f = std::clamp(x - static_cast<double>(j), 0.0, 1.0);
    w(i, j) += (1 - f) * shape.volume(i);
    w(i, j + 1) += f * shape.volume(i);
  }
  std::vector<Eigen::Index> used;
  for (Eigen::Index j = 0; j < w.cols(); ++j)
    if (w.col(j).sum() > 0) used.push_back(j);
  Eigen::MatrixXd out(n, static_cast<Eigen::Index>(used.size()));
  for (size_t k = 0; k < used.size(); ++k)
    out.col(static_cast<Eigen::Index>(k)) = w.col(used[k]) / w.col(used[k]).sum();
  return out;
}

/// Orthonormal basis under construction, in the capacity inner product. The columns live in
/// one matrix whose capacity grows geometrically, so that a new column does not copy the basis.
class CapacityOrthonormalBasis {
 public:
  CapacityOrthonormalBasis(const Sparse& capacity, double tolerance, double compression)
      : c_(capacity), tol_(tolerance), compression_(compression), v_(capacity.rows(), 0) {}

  /// Appends what each column adds to the span (block Gram-Schmidt against the basis twice, then
  /// against the block's earlier columns: "twice is enough"); returns the number of columns
  /// dropped.
  int append(Eigen::MatrixXd x) {
    Eigen::MatrixXd cx = c_ * x;
    Eigen::VectorXd norm0 = c_norms(x, cx);
    for (int pass = 0; pass < 2 && r_ > 0; ++pass) {
      if (pass > 0) cx = c_ * x;
      subtract_tall_product(x, basis_view(), tall_transposed_product(basis_view(), cx));
    }
    const Eigen::Index offered = x.cols();
    if (compression_ > 0) {
      x = compressed(std::move(x), norm0);
      norm0 = Eigen::VectorXd::Ones(x.cols());
    }
    Eigen::MatrixXd q(x.rows(), x.cols()), cq(x.rows(), x.cols());
    const Eigen::Index kept = orthonormalised_block(x, norm0, q, cq);
    reserve(r_ + kept);
    v_.middleCols(r_, kept) = q.leftCols(kept);
    r_ += kept;
    return static_cast<int>(offered - kept);
  }
  /// The basis, #nodes x r; the object is left empty.
  Eigen::MatrixXd take() {
    v_.conservativeResize(Eigen::NoChange, r_);
    r_ = 0;
    return std::move(v_);
  }

 private:
  static constexpr Eigen::Index kPanel = 16;  /// columns orthogonalised one by one at a time

  Eigen::Block<const Eigen::MatrixXd, Eigen::Dynamic, Eigen::Dynamic, true> basis_view() const {
    return v_.leftCols(r_);
  }

  void reserve(Eigen::Index columns) {
    if (columns <= v_.cols()) return;
    v_.conservativeResize(Eigen::NoChange, std::max(columns, v_.cols() + v_.cols() / 2));
  }

  /// The block x (already orthogonal to the basis) made C-orthonormal in q (cq = C q), column by
  /// column in its order, in panels: each panel against the block's kept columns twice (BLAS3),
  /// then each column against the panel's kept ones twice. A column is dropped when less than
  /// tol_ of its norm before orthogonalisation (norm0) is left. Returns the number kept.
  Eigen::Index orthonormalised_block(Eigen::MatrixXd& x, const Eigen::VectorXd& norm0,
                                     Eigen::MatrixXd& q, Eigen::MatrixXd& cq) const {
    Eigen::Index kept = 0;
    for (Eigen::Index p0 = 0; p0 < x.cols(); p0 += kPanel) {
      auto panel = x.middleCols(p0, std::min(kPanel, x.cols() - p0));
      for (int pass = 0; pass < 2 && kept > 0; ++pass)
        subtract_tall_product(panel, q.leftCols(kept),
                              tall_transposed_product(cq.leftCols(kept), panel));
      const Eigen::Index panel_start = kept;
      for (Eigen::Index j = 0; j < panel.cols(); ++j) {
        auto col = panel.col(j);
        for (int pass = 0; pass < 2 && kept > panel_start; ++pass) {
          const auto fresh = q.middleCols(panel_start, kept - panel_start);
          const auto c_fresh = cq.middleCols(panel_start, kept - panel_start);
          col -= fresh * (c_fresh.transpose() * col);  // a few columns: one thread
        }
        const Eigen::VectorXd ccol = c_ * col;
        const double norm = std::sqrt(std::max(0.0, col.dot(ccol)));
        if (!(norm0(p0 + j) > 0) || !(norm > tol_ * norm0(p0 + j))) continue;
        q.col(kept) = col / norm;
        cq.col(kept) = ccol / norm;
        ++kept;
      }
    }
    return kept;
  }

  /// The block's principal directions in the C inner product, each column scaled by its norm
  /// before orthogonalisation (every input counts alike): those whose singular value exceeds
  /// the compression tolerance, C-orthonormal.
  Eigen::MatrixXd compressed(Eigen::MatrixXd x, const Eigen::VectorXd& norm0) const {
    for (Eigen::Index j = 0; j < x.cols(); ++j)
      x.col(j) =
          norm0(j) > 0 ? Eigen::VectorXd(x.col(j) / norm0(j)) : Eigen::VectorXd::Zero(x.rows());
    const Eigen::MatrixXd g = tall_transposed_product(x, c_ * x);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(g);
    std::vector<Eigen::Index> keep;
    for (Eigen::Index i = g.rows() - 1; i >= 0; --i)
      if (eig.eigenvalues()(i) > compression_ * compression_) keep.push_back(i);
    Eigen::MatrixXd out(x.rows(), static_cast<Eigen::Index>(keep.size()));
    for (size_t k = 0; k < keep.size(); ++k)
      out.col(static_cast<Eigen::Index>(k)) =
          x * eig.eigenvectors().col(keep[k]) / std::sqrt(eig.eigenvalues()(keep[k]));
    return out;
  }
  /// Per column of x, its capacity norm, from cx = C x.
  static Eigen::VectorXd c_norms(const Eigen::MatrixXd& x, const Eigen::MatrixXd& cx) {
    return (x.cwiseProduct(cx)).colwise().sum().cwiseMax(0.0).cwiseSqrt().transpose();
  }
  const Sparse& c_;
  double tol_, compression_;
  Eigen::MatrixXd v_;  /// columns [0, r_) are the basis
  Eigen::Index r_ = 0;
};

/// The rows of a sparse matrix that hold a nonzero, ascending.
std::vector<int> nonzero_rows(const Sparse& a) {
  std::vector<char> used(static_cast<size_t>(a.rows()), 0);
  for (Eigen::Index c = 0; c < a.outerSize(); ++c)
    for (Sparse::InnerIterator it(a, c); it; ++it) used[static_cast<size_t>(it.row())] = 1;
  std::vector<int> rows;
  for (size_t i = 0; i < used.size(); ++i)
    if (used[i]) rows.push_back(static_cast<int>(i));
  return rows;
}

/// a restricted to `rows` (ascending, holding every nonzero of a), renumbered: #rows x a.cols().
Sparse rows_of(const Sparse& a, const std::vector<int>& rows) {
  std::vector<int> position(static_cast<size_t>(a.rows()), -1);
  for (size_t i = 0; i < rows.size(); ++i)
    position[static_cast<size_t>(rows[i])] = static_cast<int>(i);
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index c = 0; c < a.outerSize(); ++c)
    for (Sparse::InnerIterator it(a, c); it; ++it)
      entries.emplace_back(position[static_cast<size_t>(it.row())], static_cast<int>(c),
                           it.value());
  Sparse out(static_cast<Eigen::Index>(rows.size()), a.cols());
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

/// V^T A V for a symmetric sparse A. A film acts on a few surface nodes only: when A has nonzero
/// rows on fewer than half the nodes, the product is formed on those rows of V alone (the other
/// rows add exact zeros).
Eigen::MatrixXd symmetric_projection(const Sparse& a, const Eigen::MatrixXd& v) {
  const std::vector<int> rows = nonzero_rows(a);
  if (2 * rows.size() >= static_cast<size_t>(a.rows())) return symmetric_tall_product(v, a * v);
  const Sparse sub = rows_of(a, rows);  // #rows x #nodes; its columns outside `rows` are empty
  const Eigen::MatrixXd vs = v(rows, Eigen::placeholders::all);
  return symmetric_tall_product(vs, rows_of(Sparse(sub.transpose()), rows) * vs);
}

/// V^T P for a sparse P whose columns touch few nodes (a moving source's pieces): V's rows that
/// P touches, transposed once, so that each column of the product reads contiguous memory.
Eigen::MatrixXd projected_columns(const Eigen::MatrixXd& v, const Sparse& p) {
  const std::vector<int> rows = nonzero_rows(p);
  const Eigen::MatrixXd vt = v(rows, Eigen::placeholders::all).transpose();
  return vt * rows_of(p, rows);
}

std::string count_mismatch(const std::string& what, size_t model, size_t now) {
  return what + ": the reduced model was built with " + std::to_string(model) + ", the case has " +
         std::to_string(now);
}

bool moves(const core::CaseSpec& spec, size_t source) {
  return source < spec.thermal.sources.size() && spec.thermal.sources[source].window > 0;
}

/// The input columns before the moving sources' slices: the uniform field, the fixed sources,
/// the films' and the fluxes' areas.
Eigen::Index fixed_input_columns(const FullThermalSystem& full, const core::CaseSpec& spec) {
  Eigen::Index count = 1;
  for (size_t i = 0; i < full.source_shape.size(); ++i)
    if (!moves(spec, i)) ++count;
  return count + static_cast<Eigen::Index>(full.film_area.size() + full.flux_area.size());
}

}  // namespace

Eigen::MatrixXd input_columns(const FullThermalSystem& full, const core::CaseSpec& spec,
                              const ReductionOptions& options) {
  check_options(options);
  const Eigen::Index n = full.states();
  std::vector<Eigen::VectorXd> cols;
  cols.push_back(Eigen::VectorXd::Ones(n));
  for (size_t i = 0; i < full.source_shape.size(); ++i)
    if (!moves(spec, i)) cols.push_back(full.source_shape[i]);
  for (const auto& a : full.film_area) cols.push_back(a);
  for (const auto& a : full.flux_area) cols.push_back(a);
  for (size_t k = 0; k < full.moving.size(); ++k) {
    const double window = spec.thermal.sources[full.moving_source[k]].window;
    const double width = options.moving_slice_fraction * window;
    const Eigen::MatrixXd w = options.moving_slice_shape == ReductionOptions::SliceShape::hat
                                  ? hat_weights(full.moving_pieces[k], width)
                                  : slice_weights(full.moving_pieces[k], width);
    const Eigen::MatrixXd loads = full.moving[k] * w;
    for (Eigen::Index j = 0; j < loads.cols(); ++j) cols.push_back(loads.col(j));
  }
  Eigen::MatrixXd b(n, static_cast<Eigen::Index>(cols.size()));
  for (size_t j = 0; j < cols.size(); ++j) b.col(static_cast<Eigen::Index>(j)) = cols[j];
  return b;
}

namespace {

/// The right-hand sides of the Krylov solves: the input columns `b`, then the output columns
/// (the inputs' and the outputs' Krylov vectors come from the same factors).
Eigen::MatrixXd krylov_rhs(const FullThermalSystem& full, const Eigen::MatrixXd& b,
                           const ReductionOptions& options) {
  if (options.output_columns.size() && options.output_columns.rows() != full.states())
    throw core::SolverError("reduction: the output columns have " +
                            std::to_string(options.output_columns.rows()) +
                            " rows, the full system " + std::to_string(full.states()) + " nodes");
  Eigen::MatrixXd rhs(b.rows(), b.cols() + options.output_columns.cols());
  rhs.leftCols(b.cols()) = b;
  rhs.rightCols(options.output_columns.cols()) = options.output_columns;
  return rhs;
}

/// The shifts of each film state, in the order their Krylov vectors join the basis.
struct Shifts {
  std::vector<Sparse> stiffness;                        // K(h) per film state
  std::vector<std::pair<std::size_t, double>> shifted;  // (film state, shift)
};

/// The shifts of st.film_states; the distinct shifts are added to st.shifts_per_s.
Shifts shift_plan(const FullThermalSystem& full, const core::CaseSpec& spec,
                  const ReductionOptions& options, ReductionStats& st) {
  Shifts plan;
  for (const auto& h : st.film_states) {
    const bool steady = removes_heat(full, h);
    std::vector<double> shifts =
        options.shifts_per_s.empty() ? default_shifts(spec, steady) : options.shifts_per_s;
    plan.stiffness.push_back(film_stiffness(full, h));
    for (double s : shifts) {
      if (s == 0 && !steady) continue;  // K alone is singular: no film removes heat
      if (std::find(st.shifts_per_s.begin(), st.shifts_per_s.end(), s) == st.shifts_per_s.end())
        st.shifts_per_s.push_back(s);
      plan.shifted.emplace_back(plan.stiffness.size() - 1, s);
    }
  }
  return plan;
}

/// K(h) + s C of the i-th shift; all share one pattern.
Sparse shifted_operator(const FullThermalSystem& full, const Shifts& shifts, std::size_t i) {
  Sparse a = shifts.stiffness[shifts.shifted[i].first] + shifts.shifted[i].second * full.capacity;
  a.makeCompressed();
  return a;
}

/// The columns of x (solves of the Krylov right-hand sides: `inputs` input columns, then the
/// outputs) whose second moment is taken: all, or all but the moving sources' `slices` (the last
/// input columns before the output columns).
Eigen::MatrixXd second_moment_columns(const Eigen::MatrixXd& x, const ReductionOptions& options,
                                      Eigen::Index inputs, Eigen::Index slices) {
  if (options.moving_second_moment || slices == 0) return x;
  Eigen::MatrixXd kept(x.rows(), x.cols() - slices);
  kept << x.leftCols(inputs - slices), x.rightCols(options.output_columns.cols());
  return kept;
}

}  // namespace

Eigen::MatrixXd reduction_basis(const FullThermalSystem& full, const core::CaseSpec& spec,
                                const ReductionOptions& options, ReductionStats* stats) {
  const auto t0 = Clock::now();
  check_options(options);
  ReductionStats st;
  const Eigen::MatrixXd b = input_columns(full, spec, options);
  st.input_columns = static_cast<int>(b.cols());
  CapacityOrthonormalBasis v(full.capacity, options.deflation_tolerance,
                             options.compression_tolerance);
  // The uniform field first: every run starts from it, exactly.
  v.append(Eigen::VectorXd::Ones(full.states()));
  // The remaining input columns: the load shapes themselves (the response at s -> infinity).
  st.deflated_columns += v.append(b.rightCols(b.cols() - 1));
  st.candidate_columns = static_cast<int>(b.cols());
  const Eigen::MatrixXd rhs = krylov_rhs(full, b, options);
  st.output_columns = static_cast<int>(options.output_columns.cols());
  st.film_states = film_states(spec, options);
  const Shifts shifts = shift_plan(full, spec, options, st);
  const auto& shifted = shifts.shifted;
  // Two factors at a time, side by side (each solve needs only its own); the columns join the
  // basis in the fixed order above, so the basis does not depend on the thread count.
  // The shifted operators share one pattern: one analysis (ordering, symbolic factor) for all.
  constexpr std::size_t kWave = 2;
  const Eigen::Index slices = b.cols() - fixed_input_columns(full, spec);
  std::optional<cholmod::Analysis> analysis;
  if (!shifted.empty())
    analysis.emplace(shifted_operator(full, shifts, 0), "reduction: the pattern of K(h) + s C");
  for (std::size_t first = 0; first < shifted.size(); first += kWave) {
    const auto wave_start = Clock::now();
    const std::size_t count = std::min(kWave, shifted.size() - first);
    std::vector<std::vector<Eigen::MatrixXd>> moments(count);
    core::parallel_for(static_cast<std::ptrdiff_t>(count), [&](std::ptrdiff_t i) {
      const std::size_t at = first + static_cast<std::size_t>(i);
      std::ostringstream what;
      what << "reduction: K(h) + s C at s = " << shifted[at].second << " 1/s";
      const cholmod::Factor factor(*analysis, shifted_operator(full, shifts, at), what.str());
      auto& out = moments[static_cast<std::size_t>(i)];
      out.push_back(factor.solve(rhs));
      if (options.second_moment)
        out.push_back(factor.solve(full.capacity *
                                   second_moment_columns(out.back(), options, b.cols(), slices)));
    });
    const auto solved = Clock::now();
    st.solve_s += std::chrono::duration<double>(solved - wave_start).count();
    for (auto& block : moments)
      for (auto& x : block) {
        st.candidate_columns += static_cast<int>(x.cols());
        st.deflated_columns += v.append(x);
      }
    st.factorizations += static_cast<int>(count);
    st.orthogonalise_s += std::chrono::duration<double>(Clock::now() - solved).count();
  }
  st.build_s = std::chrono::duration<double>(Clock::now() - t0).count();
  if (stats) *stats = st;
  return v.take();
}

namespace {

/// The Galerkin projection on `basis` with the reduced capacity V^T C V already known.
ReducedThermalSystem projected_with_capacity(const FullThermalSystem& full,
                                             const Eigen::MatrixXd& basis,
                                             Eigen::MatrixXd capacity) {
  ReducedThermalSystem r;
  r.capacity = std::move(capacity);
  r.conduction = symmetric_projection(full.conduction, basis);
  for (const auto& f : full.film) r.film.push_back(symmetric_projection(f, basis));
  const auto project = [&](const std::vector<Eigen::VectorXd>& in) {
    std::vector<Eigen::VectorXd> out;
    for (const auto& x : in) out.push_back(basis.transpose() * x);
    return out;
  };
  r.film_area = project(full.film_area);
  r.source_shape = project(full.source_shape);
  r.flux_area = project(full.flux_area);
  for (const auto& p : full.moving) r.moving.push_back(projected_columns(basis, p));
  r.moving_source = full.moving_source;
  r.moving_pieces = full.moving_pieces;
  // The uniform field's coordinates: its capacity-weighted projection on the basis,
  // (V^T C V)^{-1} V^T C 1, exact since the basis holds it. V^T C V is I for the system the basis
  // was built on, not for another capacity projected on it (a calibrated case).
  r.uniform = r.capacity.ldlt().solve(basis.transpose() *
                                      (full.capacity * Eigen::VectorXd::Ones(full.states())));
  return with_moving_prefix(std::move(r));
}

}  // namespace

ReducedThermalSystem projected_system(const FullThermalSystem& full, const Eigen::MatrixXd& basis) {
  if (basis.rows() != full.states())
    throw core::SolverError("reduction: the basis has " + std::to_string(basis.rows()) +
                            " rows, the full system " + std::to_string(full.states()) + " nodes");
  return projected_with_capacity(full, basis, symmetric_projection(full.capacity, basis));
}

ReducedModel reduced_model(const FullThermalSystem& full, const core::CaseSpec& spec,
                           const ReductionOptions& options) {
  const auto t0 = Clock::now();
  ReducedModel m;
  m.basis = reduction_basis(full, spec, options, &m.stats);
  const auto projection_start = Clock::now();
  // The basis was made C-orthonormal against this capacity (Gram-Schmidt twice), so V^T C V is I
  // to rounding (ReductionBasis.IsCapacityOrthonormalAndHoldsTheUniformField: within 1e-10);
  // forming it would cost a pass over n x r^2, about 40 % of the projection on GM-1.
  m.system =
      projected_with_capacity(full, m.basis, Eigen::MatrixXd::Identity(m.states(), m.states()));
  m.stats.projection_s = std::chrono::duration<double>(Clock::now() - projection_start).count();
  m.stats.build_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return m;
}

Eigen::MatrixXd project_rows(const ReducedModel& model, const Eigen::SparseMatrix<double>& rows) {
  if (rows.cols() != model.basis.rows())
    throw core::SolverError("reduction: output rows have " + std::to_string(rows.cols()) +
                            " columns, the reduced model's mesh " +
                            std::to_string(model.basis.rows()) + " nodes");
  return rows * model.basis;
}

Eigen::MatrixXd project_rows(const ReducedModel& model, const Eigen::MatrixXd& rows) {
  if (rows.cols() != model.basis.rows())
    throw core::SolverError("reduction: output rows have " + std::to_string(rows.cols()) +
                            " columns, the reduced model's mesh " +
                            std::to_string(model.basis.rows()) + " nodes");
  return rows * model.basis;
}

Eigen::MatrixXd reconstructed(const ReducedModel& model, const Eigen::MatrixXd& states) {
  if (states.rows() != model.basis.cols())
    throw core::SolverError("reduction: states have " + std::to_string(states.rows()) +
                            " rows, the reduced model " + std::to_string(model.basis.cols()));
  return model.basis * states;
}

void check_reducible(const ReducedModel& model, const FullThermalSystem& full,
                     const core::CaseSpec& spec) {
  const auto fail = [](const std::string& what) {
    throw core::SolverError("reduced model does not fit this case: " + what +
                            ". Hint: build the reduced model again from this case and mesh");
  };
  if (model.basis.rows() != full.states())
    fail(count_mismatch("nodes", static_cast<size_t>(model.basis.rows()),
                        static_cast<size_t>(full.states())));
  const auto& sys = model.system;
  if (sys.film.size() != spec.thermal.convection.size())
    fail(count_mismatch("thermal.convection entries", sys.film.size(),
                        spec.thermal.convection.size()));
  if (sys.source_shape.size() != spec.thermal.sources.size())
    fail(count_mismatch("thermal.heat_sources", sys.source_shape.size(),
                        spec.thermal.sources.size()));
  if (sys.flux_area.size() != spec.thermal.fluxes.size())
    fail(count_mismatch("thermal.fluxes", sys.flux_area.size(), spec.thermal.fluxes.size()));
  std::vector<int> moving;
  for (size_t i = 0; i < spec.thermal.sources.size(); ++i)
    if (spec.thermal.sources[i].window > 0) moving.push_back(static_cast<int>(i));
  if (moving != sys.moving_source)
    fail("the heat sources that move with the feed axis differ (" +
         std::to_string(sys.moving_source.size()) + " in the model, " +
         std::to_string(moving.size()) + " in the case)");
}

namespace {

void check_step(const FullThermalSystem& full, const Eigen::MatrixXd& basis,
                const ReducedStep& step) {
  const Eigen::Index n = full.states();
  if (basis.rows() != n || step.state_old.size() != basis.cols() ||
      step.state_new.size() != basis.cols() || step.load.size() != n ||
      step.film.size() != full.film.size() || !(step.dt > 0))
    throw core::SolverError(
        "reduction error indicator: the sampled step does not fit the system (basis " +
        std::to_string(basis.rows()) + " x " + std::to_string(basis.cols()) + ", states " +
        std::to_string(step.state_old.size()) + " and " + std::to_string(step.state_new.size()) +
        ", load " + std::to_string(step.load.size()) + ", " + std::to_string(step.film.size()) +
        " film coefficients, dt = " + std::to_string(step.dt) + " s)");
}

/// The step's full-order residual [W].
Eigen::VectorXd step_residual(const FullThermalSystem& full, const Eigen::MatrixXd& basis,
                              const Sparse& k, const ReducedStep& step) {
  const Eigen::VectorXd t_old = basis * step.state_old, t_new = basis * step.state_new;
  const Eigen::VectorXd mid = step.theta * t_new + (1 - step.theta) * t_old;
  return full.capacity * ((t_new - t_old) / step.dt) + k * mid - step.load;
}

/// The horizon rounded to a power of sqrt(2) (at least dt) [s], so that samples share factors.
double rounded_horizon(const ReducedStep& step) {
  const double tau = std::max(step.dt, step.horizon);
  return std::pow(std::sqrt(2.0), std::round(std::log(tau) / std::log(std::sqrt(2.0))));
}

/// max |e| of the residuals [K], e = (K(h) + C/tau)^{-1} r, one factor for all of them.
Eigen::VectorXd estimates(const FullThermalSystem& full, const Sparse& k, double tau,
                          const Eigen::MatrixXd& residuals) {
  Sparse a = k + (1.0 / tau) * full.capacity;
  a.makeCompressed();
  std::ostringstream what;
  what << "reduction error indicator: K(h) + C/tau at tau = " << tau << " s";
  const cholmod::Factor factor(a, what.str());
  return factor.solve(residuals).cwiseAbs().colwise().maxCoeff().transpose();
}

}  // namespace

double step_error_estimate(const FullThermalSystem& full, const Eigen::MatrixXd& basis,
                           const ReducedStep& step) {
  check_step(full, basis, step);
  const Sparse k = film_stiffness(full, step.film);
  return estimates(full, k, rounded_horizon(step), step_residual(full, basis, k, step))(0);
}

ErrorIndicator error_indicator(const FullThermalSystem& full, const ReducedModel& model,
                               const std::vector<ReducedStep>& steps, double tolerance_k) {
  ErrorIndicator out;
  out.tolerance_k = tolerance_k;
  out.samples_k.assign(steps.size(), 0.0);
  for (const auto& s : steps) check_step(full, model.basis, s);
  // Samples grouped by (film state, rounded horizon): one factor and one block solve per group,
  // the groups side by side (each writes its own samples only).
  std::vector<bool> grouped(steps.size(), false);
  std::vector<std::vector<size_t>> groups;
  for (size_t i = 0; i < steps.size(); ++i) {
    if (grouped[i]) continue;
    const double tau = rounded_horizon(steps[i]);
    groups.emplace_back();
    for (size_t j = i; j < steps.size(); ++j)
      if (!grouped[j] && steps[j].film == steps[i].film && rounded_horizon(steps[j]) == tau) {
        groups.back().push_back(j);
        grouped[j] = true;
      }
  }
  core::parallel_for(static_cast<std::ptrdiff_t>(groups.size()), [&](std::ptrdiff_t gi) {
    const auto& group = groups[static_cast<size_t>(gi)];
    const ReducedStep& first = steps[group.front()];
    const Sparse k = film_stiffness(full, first.film);
    Eigen::MatrixXd r(full.states(), static_cast<Eigen::Index>(group.size()));
    for (size_t g = 0; g < group.size(); ++g)
      r.col(static_cast<Eigen::Index>(g)) = step_residual(full, model.basis, k, steps[group[g]]);
    const Eigen::VectorXd e = estimates(full, k, rounded_horizon(first), r);
    for (size_t g = 0; g < group.size(); ++g)
      out.samples_k[group[g]] = e(static_cast<Eigen::Index>(g));
  });
  for (double e : out.samples_k) out.max_k = std::max(out.max_k, e);
  return out;
}

}  // namespace tt::solvers
