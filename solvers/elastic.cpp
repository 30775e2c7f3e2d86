#include "solvers/elastic.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/errors.hpp"
#include "core/finite.hpp"
#include "core/parallel.hpp"
#include "solvers/cholmod/cholmod_factor.hpp"
#include "solvers/kernels/elasticity.hpp"
#include "solvers/kernels/element.hpp"
#include "solvers/thermal.hpp"

namespace tt::solvers {
namespace {

namespace k = kernels;
using Triplets = std::vector<Eigen::Triplet<double>>;
using Clock = std::chrono::steady_clock;

template <int N>
Eigen::Matrix<double, 3, N> coords(const mesh::TetMesh& m, int t) {
  Eigen::Matrix<double, 3, N> x;
  for (int a = 0; a < N; ++a) x.col(a) = m.nodes.row(m.tets(t, a)).transpose();
  return x;
}

k::ElasticMaterial elastic_material(const mesh::TetMesh& m, const core::CaseSpec& spec, int t) {
  const auto& mat = spec.materials[spec.bodies[core::index_of(m.tet_region[t])].material];
  return k::ElasticMaterial{mat.youngs_modulus, mat.poisson_ratio, mat.expansion};
}

/// Stiffness K (3n x 3n, upper triangle only: K is symmetric and CHOLMOD reads no more) and
/// thermal coupling G (3n x n): f_thermal = G (T - T_ref).
template <int N>
std::pair<Eigen::SparseMatrix<double>, Eigen::SparseMatrix<double>> assemble(
    const mesh::TetMesh& m, const core::CaseSpec& spec) {
  for (int t = 0; t < m.tets.rows(); ++t) {
    if (!(k::min_jacobian_determinant(coords<N>(m, t)) > 0))
      throw core::SolverError("element " + std::to_string(t) + " is inverted or degenerate");
    k::elasticity_matrix(elastic_material(m, spec, t));  // validates E and nu outside the loop
  }
  const int n = static_cast<int>(m.nodes.rows());
  auto parts = core::parallel_chunks<std::pair<Triplets, Triplets>>(
      m.tets.rows(), 2048, [&](std::ptrdiff_t b, std::ptrdiff_t e, std::ptrdiff_t) {
        std::pair<Triplets, Triplets> out;
        out.first.reserve((e - b) * 3 * N * (3 * N + 1) / 2);
        out.second.reserve((e - b) * 3 * N * N);
        for (auto t = b; t < e; ++t) {
          const int ti = static_cast<int>(t);
          const auto x = coords<N>(m, ti);
          const auto mat = elastic_material(m, spec, ti);
          const auto ke = k::stiffness_matrix(x, mat, ti);
          for (int i = 0; i < 3 * N; ++i)
            for (int j = 0; j < 3 * N; ++j) {
              const int row = 3 * m.tets(ti, i / 3) + i % 3, col = 3 * m.tets(ti, j / 3) + j % 3;
              if (row <= col) out.first.emplace_back(row, col, ke(i, j));
            }
          const auto g = k::thermal_coupling_matrix(x, mat, ti);
          for (int j = 0; j < N; ++j)
            for (int i = 0; i < 3 * N; ++i)
              out.second.emplace_back(3 * m.tets(ti, i / 3) + i % 3, m.tets(ti, j), g(i, j));
        }
        return out;
      });
  // Gathered chunk by chunk, each chunk freed once copied, so that the triplets are held about
  // once rather than twice.
  std::size_t kn = 0, gn = 0;
  for (const auto& p : parts) kn += p.first.size(), gn += p.second.size();
  Triplets kt, gt;
  kt.reserve(kn);
  gt.reserve(gn);
  for (auto& p : parts) {
    kt.insert(kt.end(), p.first.begin(), p.first.end());
    gt.insert(gt.end(), p.second.begin(), p.second.end());
    p = {};
  }
  Eigen::SparseMatrix<double> kk(3 * n, 3 * n), g(3 * n, n);
  kk.setFromTriplets(kt.begin(), kt.end());
  g.setFromTriplets(gt.begin(), gt.end());
  kk.makeCompressed();
  g.makeCompressed();
  return {std::move(kk), std::move(g)};
}

template <int N>
Eigen::VectorXd von_mises_impl(const mesh::TetMesh& m, const core::CaseSpec& spec,
                               const Eigen::VectorXd& u, const Eigen::VectorXd& temp) {
  const double tref = spec.mechanical.reference_temperature_c + core::kCelsiusOffset;
  const int n = static_cast<int>(m.nodes.rows());
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n), count = Eigen::VectorXd::Zero(n);
  for (int t = 0; t < m.tets.rows(); ++t) {
    Eigen::Matrix<double, 3 * N, 1> ue;
    Eigen::Matrix<double, N, 1> te;
    for (int a = 0; a < N; ++a) {
      te(a) = temp(m.tets(t, a));
      for (int d = 0; d < 3; ++d) ue(3 * a + d) = u(3 * m.tets(t, a) + d);
    }
    const auto s =
        k::nodal_stresses(coords<N>(m, t), elastic_material(m, spec, t), ue, te, tref, t);
    for (int a = 0; a < N; ++a) {
      sum(m.tets(t, a)) += k::von_mises(s.col(a));
      count(m.tets(t, a)) += 1;
    }
  }
  return sum.cwiseQuotient(count.cwiseMax(1.0));
}

}  // namespace

std::vector<char> constrained_dofs(const mesh::TetMesh& m, const core::CaseSpec& spec) {
  const int n = static_cast<int>(m.nodes.rows());
  std::vector<char> fixed(3 * static_cast<size_t>(n), 0);
  for (int f = 0; f < m.faces.rows(); ++f) {
    const int g = core::index_of(m.face_group[f]);
    for (int fg : spec.mechanical.fixed_groups)
      if (g == fg)
        for (int a = 0; a < m.faces.cols(); ++a)
          for (int d = 0; d < 3; ++d) fixed[3 * m.faces(f, a) + d] = 1;
  }
  for (const auto& s : spec.mechanical.point_supports) {
    const int node = mesh::named_node(m, s.point);
    if (node < 0) throw core::SolverError("mechanical support at unknown point '" + s.point + "'");
    for (int d = 0; d < 3; ++d)
      if (s.fixed[d]) fixed[3 * node + d] = 1;
  }
  // The six rigid motions restricted to the held dofs must be independent.
  Eigen::Vector3d centre = m.nodes.colwise().mean().transpose();
  std::vector<Eigen::Matrix<double, 1, 6>> rows;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d r = m.nodes.row(i).transpose() - centre;
    for (int d = 0; d < 3; ++d) {
      if (!fixed[3 * i + d]) continue;
      Eigen::Matrix<double, 1, 6> row = Eigen::Matrix<double, 1, 6>::Zero();
      row(d) = 1;
      const Eigen::Vector3d e = Eigen::Vector3d::Unit(d);
      for (int a = 0; a < 3; ++a) row(3 + a) = Eigen::Vector3d::Unit(a).cross(r).dot(e);
      rows.push_back(row);
    }
  }
  Eigen::MatrixXd c(static_cast<Eigen::Index>(rows.size()), 6);
  for (size_t i = 0; i < rows.size(); ++i) c.row(static_cast<Eigen::Index>(i)) = rows[i];
  const int rank =
      rows.empty() ? 0 : static_cast<int>(Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(c).rank());
  if (rank < 6)
    throw core::SolverError("mechanical constraints leave " + std::to_string(6 - rank) +
                            " rigid motion(s) free (" + std::to_string(rows.size()) +
                            " dofs held): the displacement would be undetermined. Hint: list a "
                            "boundary group in mechanical.fixed or add point supports.");
  return fixed;
}

struct ElasticModel::Impl {
  Eigen::SparseMatrix<double> coupling;  // G, 3n x n [N/K]
  std::vector<int> free_index;           // per dof: index among free dofs, -1 when held
  int free_dofs = 0;
  std::unique_ptr<cholmod::Factor> factor;
};

ElasticModel::ElasticModel(const mesh::TetMesh& m, const core::CaseSpec& spec)
    : impl_(std::make_unique<Impl>()) {
  const auto t0 = Clock::now();
  const std::vector<char> fixed = constrained_dofs(m, spec);
  // The free-dof stiffness, upper triangle only (all CHOLMOD reads), built in a scope of its own
  // so that the full stiffness and the triplets are freed before the factor takes its memory; the
  // matrix itself is freed once factored. On the refined SB-1 mesh (1.1 M dofs) the factor alone
  // is about 15 GB, so what lives beside it decides whether the run fits.
  Eigen::SparseMatrix<double> kf;
  int ndof = 0;
  {
    auto [kk, g] = m.order == 1 ? assemble<4>(m, spec) : assemble<10>(m, spec);
    ndof = static_cast<int>(kk.rows());
    impl_->free_index.assign(ndof, -1);
    int nf = 0;
    for (int i = 0; i < ndof; ++i)
      if (!fixed[i]) impl_->free_index[i] = nf++;
    Triplets ft;
    for (int col = 0; col < kk.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(kk, col); it; ++it) {
        // Free indices keep the global order, so the upper triangle stays upper.
        const int r = impl_->free_index[it.row()], c = impl_->free_index[col];
        if (r >= 0 && c >= 0) ft.emplace_back(r, c, it.value());
      }
    kk = Eigen::SparseMatrix<double>();
    kf.resize(nf, nf);
    kf.setFromTriplets(ft.begin(), ft.end());
    kf.makeCompressed();
    impl_->coupling = std::move(g);
    impl_->free_dofs = nf;
  }
  timings_.assemble_s = std::chrono::duration<double>(Clock::now() - t0).count();
  timings_.dofs = ndof;
  timings_.free_dofs = impl_->free_dofs;
  const auto t1 = Clock::now();
  impl_->factor = std::make_unique<cholmod::Factor>(kf, "elastic stiffness");
  kf = Eigen::SparseMatrix<double>();
  timings_.factor_s = std::chrono::duration<double>(Clock::now() - t1).count();
  reference_k_ = spec.mechanical.reference_temperature_c + core::kCelsiusOffset;
}

ElasticModel::~ElasticModel() = default;
ElasticModel::ElasticModel(ElasticModel&&) noexcept = default;

Eigen::MatrixXd ElasticModel::displacements(const Eigen::MatrixXd& temperature) const {
  if (temperature.rows() != impl_->coupling.cols())
    throw core::SolverError("temperature fields have " + std::to_string(temperature.rows()) +
                            " rows, expected one per mesh node (" +
                            std::to_string(impl_->coupling.cols()) +
                            "). Hint: on a 10-node mesh give mid-edge nodes too.");
  // The output times go through the factor as multi-right-hand-side blocks of a bounded width:
  // one block for all times would hold five dense copies of #dofs x #times beside the factor.
  constexpr Eigen::Index kBlock = 16;
  const int ndof = static_cast<int>(impl_->coupling.rows());
  const Eigen::Index times = temperature.cols();
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(ndof, times);
  for (Eigen::Index first = 0; first < times; first += kBlock) {
    const Eigen::Index width = std::min(kBlock, times - first);
    const Eigen::MatrixXd load =
        impl_->coupling * (temperature.middleCols(first, width).array() - reference_k_).matrix();
    Eigen::MatrixXd rhs(impl_->free_dofs, width);
    for (int i = 0; i < ndof; ++i)
      if (impl_->free_index[i] >= 0) rhs.row(impl_->free_index[i]) = load.row(i);
    const Eigen::MatrixXd uf = impl_->factor->solve(rhs);
    for (int i = 0; i < ndof; ++i)
      if (impl_->free_index[i] >= 0) u.block(i, first, 1, width) = uf.row(impl_->free_index[i]);
  }
  return u;
}

namespace {

/// Per-material influence rows: sum over material m's tets of (W_e^T g_e), W the adjoint
/// solutions (3 #nodes x #rows), g_e the element's thermal coupling.
template <int N>
std::vector<Eigen::MatrixXd> rows_by_material(const mesh::TetMesh& m, const core::CaseSpec& spec,
                                              const Eigen::MatrixXd& w) {
  const Eigen::Index rows = w.cols();
  std::vector<Eigen::MatrixXd> out(spec.materials.size(),
                                   Eigen::MatrixXd::Zero(rows, m.nodes.rows()));
  Eigen::MatrixXd we(3 * N, rows);
  for (int t = 0; t < m.tets.rows(); ++t) {
    const int mat = spec.bodies[core::index_of(m.tet_region[t])].material;
    const auto g = k::thermal_coupling_matrix(coords<N>(m, t), elastic_material(m, spec, t), t);
    for (int i = 0; i < 3 * N; ++i) we.row(i) = w.row(3 * m.tets(t, i / 3) + i % 3);
    const Eigen::MatrixXd part = we.transpose() * g;  // #rows x N
    for (int j = 0; j < N; ++j) out[static_cast<size_t>(mat)].col(m.tets(t, j)) += part.col(j);
  }
  return out;
}

}  // namespace

Eigen::VectorXd ElasticModel::influence(int node, int direction) const {
  return influence_rows({{node, direction}}).row(0).transpose();
}

Eigen::SparseMatrix<double> ElasticModel::unit_functionals(
    const std::vector<std::pair<int, int>>& node_directions) const {
  std::vector<Eigen::Triplet<double>> unit;
  for (const auto& [node, direction] : node_directions) {
    if (node < 0 || node >= impl_->coupling.cols() || direction < 0 || direction > 2)
      throw core::SolverError("influence at node " + std::to_string(node) + ", direction " +
                              std::to_string(direction) + ": expected 0 <= node < " +
                              std::to_string(impl_->coupling.cols()) + " and direction 0, 1 or 2");
    unit.emplace_back(static_cast<int>(unit.size()), 3 * node + direction, 1.0);
  }
  Eigen::SparseMatrix<double> f(static_cast<Eigen::Index>(unit.size()), impl_->coupling.rows());
  f.setFromTriplets(unit.begin(), unit.end());
  return f;
}

Eigen::MatrixXd ElasticModel::influence_rows(
    const std::vector<std::pair<int, int>>& node_directions) const {
  return influence_rows(unit_functionals(node_directions));
}

Eigen::MatrixXd ElasticModel::adjoint_solutions(
    const Eigen::SparseMatrix<double>& functionals) const {
  const Impl& impl = *impl_;
  const int ndof = static_cast<int>(impl.coupling.rows());
  if (functionals.cols() != ndof)
    throw core::SolverError("displacement functionals have " + std::to_string(functionals.cols()) +
                            " columns, expected 3 per node (" + std::to_string(ndof) + ")");
  // K is symmetric: f . u = f^T K^-1 G dT = (G^T K^-1 f)^T dT.
  const Eigen::MatrixXd dense = Eigen::MatrixXd(functionals.transpose());
  Eigen::MatrixXd rhs(impl.free_dofs, functionals.rows());
  for (int i = 0; i < ndof; ++i)
    if (impl.free_index[i] >= 0) rhs.row(impl.free_index[i]) = dense.row(i);
  const Eigen::MatrixXd wf = impl.factor->solve(rhs);
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(ndof, functionals.rows());
  for (int i = 0; i < ndof; ++i)
    if (impl.free_index[i] >= 0) w.row(i) = wf.row(impl.free_index[i]);
  return w;
}

Eigen::MatrixXd ElasticModel::influence_rows(const Eigen::SparseMatrix<double>& functionals) const {
  return (impl_->coupling.transpose() * adjoint_solutions(functionals)).transpose();
}

std::vector<Eigen::MatrixXd> ElasticModel::split_by_material(const Eigen::MatrixXd& w,
                                                             const mesh::TetMesh& mesh,
                                                             const core::CaseSpec& spec) const {
  if (mesh.nodes.rows() != impl_->coupling.cols())
    throw core::SolverError("influence rows by material: the mesh has " +
                            std::to_string(mesh.nodes.rows()) + " nodes, the model " +
                            std::to_string(impl_->coupling.cols()));
  return mesh.order == 1 ? rows_by_material<4>(mesh, spec, w) : rows_by_material<10>(mesh, spec, w);
}

std::vector<Eigen::MatrixXd> ElasticModel::influence_rows_by_material(
    const Eigen::SparseMatrix<double>& functionals, const mesh::TetMesh& mesh,
    const core::CaseSpec& spec) const {
  return split_by_material(adjoint_solutions(functionals), mesh, spec);
}

ElasticModel::SplitRows ElasticModel::influence_rows_split(
    const std::vector<std::pair<int, int>>& node_directions, const mesh::TetMesh& mesh,
    const core::CaseSpec& spec) const {
  const Eigen::MatrixXd w = adjoint_solutions(unit_functionals(node_directions));
  return {(impl_->coupling.transpose() * w).transpose(), split_by_material(w, mesh, spec)};
}

ElasticHistory elastic_history(const mesh::TetMesh& m, const core::CaseSpec& spec,
                               const Eigen::MatrixXd& temperature) {
  const ElasticModel model(m, spec);
  ElasticHistory h;
  const auto t2 = Clock::now();
  h.displacement = model.displacements(temperature);
  h.timings = model.timings();
  h.timings.solve_s = std::chrono::duration<double>(Clock::now() - t2).count();
  core::require_finite(h.displacement,
                       "the displacement [m] (row: 3 x node + direction, column: output time)",
                       "the thermal strain of the temperatures overflowed (peak " +
                           std::to_string(temperature.maxCoeff() - core::kCelsiusOffset) +
                           " degC); check the heat loads and expansion_per_K, youngs_modulus_Pa");
  return h;
}

Eigen::VectorXd von_mises_nodal(const mesh::TetMesh& m, const core::CaseSpec& spec,
                                const Eigen::VectorXd& u, const Eigen::VectorXd& temp) {
  if (u.size() != 3 * m.nodes.rows() || temp.size() != m.nodes.rows())
    throw core::SolverError("von Mises: " + std::to_string(u.size()) + " displacements and " +
                            std::to_string(temp.size()) +
                            " temperatures, expected 3 and 1 per node (" +
                            std::to_string(m.nodes.rows()) + " nodes)");
  return m.order == 1 ? von_mises_impl<4>(m, spec, u, temp) : von_mises_impl<10>(m, spec, u, temp);
}

Eigen::Vector3d displacement_at(const mesh::TetMesh& m, const Eigen::VectorXd& u,
                                const Eigen::Vector3d& p) {
  if (u.size() != 3 * m.nodes.rows())
    throw core::SolverError("displacement vector has " + std::to_string(u.size()) +
                            " entries, expected " + std::to_string(3 * m.nodes.rows()) +
                            " (3 per node)");
  for (int t = 0; t < m.tets.rows(); ++t) {
    const auto x4 = coords<4>(m, t);
    Eigen::Vector3d lo = x4.rowwise().minCoeff(), hi = x4.rowwise().maxCoeff();
    if ((p.array() < lo.array() - 1e-12).any() || (p.array() > hi.array() + 1e-12).any()) continue;
    const Eigen::Vector4d bary = k::tet_barycentric(x4, p, t);
    if (bary.minCoeff() < -1e-10) continue;
    Eigen::Vector3d result = Eigen::Vector3d::Zero();
    if (m.order == 1) {
      for (int a = 0; a < 4; ++a) result += bary(a) * u.segment<3>(3 * m.tets(t, a));
    } else {
      const auto w = k::tet10_weights_at(coords<10>(m, t), p, t);
      for (int a = 0; a < 10; ++a) result += w(a) * u.segment<3>(3 * m.tets(t, a));
    }
    return result;
  }
  throw core::SolverError("point (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " +
                          std::to_string(p.z()) + ") m lies outside the mesh");
}

}  // namespace tt::solvers
