#include "solvers/feed_axis.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/errors.hpp"
#include "solvers/kernels/heat.hpp"
#include "solvers/loads.hpp"

namespace tt::solvers {
namespace {

template <int N>
MovingSourceShape shape_of(const mesh::TetMesh& m, const core::CaseSpec& spec, int source) {
  const auto& src = spec.thermal.sources[source];
  const int dir = spec.feed_axis.direction;
  std::vector<int> tets;
  std::vector<double> centre;
  for (int t = 0; t < m.tets.rows(); ++t) {
    if (core::index_of(m.tet_region[t]) != src.body) continue;
    tets.push_back(t);
    double c = 0;
    for (int a = 0; a < 4; ++a) c += m.nodes(m.tets(t, a), dir);
    centre.push_back(c / 4);
  }
  if (tets.empty())
    throw core::SolverError("thermal.heat_sources '" + src.name + "': body '" +
                            spec.bodies[src.body].name +
                            "' has no elements, so its moving heat cannot go anywhere");
  std::vector<size_t> order(tets.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return centre[a] < centre[b]; });
  MovingSourceShape s;
  s.source = source;
  const auto n = static_cast<Eigen::Index>(tets.size());
  s.centre.resize(n);
  s.volume.resize(n);
  s.nodes.resize(n, N);
  s.weight.resize(n, N);
  for (Eigen::Index i = 0; i < n; ++i) {
    const int t = tets[order[static_cast<size_t>(i)]];
    Eigen::Matrix<double, 3, N> x;
    for (int a = 0; a < N; ++a) x.col(a) = m.nodes.row(m.tets(t, a)).transpose();
    s.centre(i) = centre[order[static_cast<size_t>(i)]];
    s.volume(i) = kernels::element_volume(x, t);
    s.weight.row(i) = kernels::source_vector(x, 1.0, t).transpose();
    for (int a = 0; a < N; ++a) s.nodes(i, a) = m.tets(t, a);
  }
  return s;
}

}  // namespace

std::vector<MovingSourceShape> moving_source_shapes(const mesh::TetMesh& mesh,
                                                    const core::CaseSpec& spec) {
  std::vector<MovingSourceShape> out;
  for (size_t i = 0; i < spec.thermal.sources.size(); ++i) {
    if (!(spec.thermal.sources[i].window > 0)) continue;
    const int s = static_cast<int>(i);
    out.push_back(mesh.order == 1 ? shape_of<4>(mesh, spec, s) : shape_of<10>(mesh, spec, s));
  }
  return out;
}

Eigen::SparseMatrix<double> moving_load_matrix(const MovingSourceShape& shape, Eigen::Index nodes) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(shape.weight.size()));
  for (Eigen::Index p = 0; p < shape.nodes.rows(); ++p)
    for (Eigen::Index a = 0; a < shape.nodes.cols(); ++a)
      entries.emplace_back(shape.nodes(p, a), p, shape.weight(p, a) / shape.volume(p));
  Eigen::SparseMatrix<double> load(nodes, shape.nodes.rows());
  load.setFromTriplets(entries.begin(), entries.end());
  load.makeCompressed();
  return load;
}

std::vector<WindowShare> moving_windows(const core::CaseSpec& spec, const MovingSourceShape& shape,
                                        double t0, double t1) {
  const auto& src = spec.thermal.sources[shape.source];
  const auto n = shape.centre.size();
  const double* begin = shape.centre.data();
  const double* end = begin + n;
  const double travel = feed_speed_at(spec.feed_axis, 0.5 * (t0 + t1)) * (t1 - t0);
  const int k = std::clamp(static_cast<int>(std::ceil(8 * travel / src.window)), 1, 4096);
  Eigen::VectorXd prefix(n + 1);  // prefix volumes
  prefix(0) = 0;
  for (Eigen::Index i = 0; i < n; ++i) prefix(i + 1) = prefix(i) + shape.volume(i);
  std::vector<WindowShare> windows;
  windows.reserve(static_cast<std::size_t>(k));
  for (int j = 0; j < k; ++j) {
    const double t = t0 + (j + 0.5) * (t1 - t0) / k;
    const double c = axis_position_at(spec.feed_axis, t) + src.window_offset;
    auto lo = static_cast<Eigen::Index>(std::lower_bound(begin, end, c - 0.5 * src.window) - begin);
    auto hi = static_cast<Eigen::Index>(std::upper_bound(begin, end, c + 0.5 * src.window) - begin);
    if (lo >= hi) {  // no centroid in the window: the nearest piece
      const auto at = static_cast<Eigen::Index>(std::lower_bound(begin, end, c) - begin);
      lo = at >= n || (at > 0 && c - shape.centre(at - 1) <= shape.centre(at) - c) ? at - 1 : at;
      hi = lo + 1;
    }
    windows.push_back({lo, hi, 1.0 / (k * (prefix(hi) - prefix(lo)))});
  }
  return windows;
}

Eigen::VectorXd moving_piece_fractions(const core::CaseSpec& spec, const MovingSourceShape& shape,
                                       double t0, double t1) {
  const auto n = shape.centre.size();
  Eigen::VectorXd diff = Eigen::VectorXd::Zero(n + 1);  // a difference array of the shares
  for (const WindowShare& w : moving_windows(spec, shape, t0, t1)) {
    diff(w.lo) += w.per_volume;
    diff(w.hi) -= w.per_volume;
  }
  Eigen::VectorXd fraction(n);
  double density = 0;  // fraction per unit volume
  for (Eigen::Index i = 0; i < n; ++i) {
    density += diff(i);
    fraction(i) = density * shape.volume(i);
  }
  return fraction;
}

Eigen::MatrixXd moving_prefix(const Eigen::MatrixXd& load, const MovingSourceShape& shape) {
  if (load.cols() != shape.volume.size())
    throw core::SolverError("moving load: " + std::to_string(load.cols()) + " columns for " +
                            std::to_string(shape.volume.size()) + " pieces");
  Eigen::MatrixXd prefix(load.rows(), load.cols() + 1);
  prefix.col(0).setZero();
  for (Eigen::Index i = 0; i < load.cols(); ++i)
    prefix.col(i + 1) = prefix.col(i) + shape.volume(i) * load.col(i);
  return prefix;
}

}  // namespace tt::solvers
