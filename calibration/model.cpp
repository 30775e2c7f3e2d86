#include "calibration/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "core/errors.hpp"
#include "solvers/cholmod/cholmod_factor.hpp"
#include "solvers/elastic.hpp"
#include "solvers/kernels/element.hpp"
#include "solvers/loads.hpp"
#include "solvers/thermal.hpp"

namespace tt::calibration {

namespace {

constexpr double kCelsius = 273.15;

/// Barycentric coordinates of p in tet `e` from its corners, without throwing on bad tets.
Eigen::Vector4d barycentric(const mesh::TetMesh& m, int e, const Eigen::Vector3d& p) {
  Eigen::Matrix3d a;
  const Eigen::Vector3d x0 = m.nodes.row(m.tets(e, 0)).transpose();
  for (int k = 0; k < 3; ++k) a.col(k) = m.nodes.row(m.tets(e, k + 1)).transpose() - x0;
  const double det = a.determinant();
  if (!(std::abs(det) > 0)) return Eigen::Vector4d::Constant(-1e300);
  const Eigen::Vector3d l = a.inverse() * (p - x0);
  return Eigen::Vector4d(1 - l.sum(), l(0), l(1), l(2));
}

/// Values at the grid times, linearly interpolated at `times` (constant beyond the ends).
Eigen::MatrixXd sample_at(const std::vector<double>& grid,
                          const std::vector<Eigen::VectorXd>& values,
                          const Eigen::VectorXd& times) {
  const Eigen::Index c = values.front().size();
  Eigen::MatrixXd out(times.size(), c);
  size_t j = 0;
  for (Eigen::Index i = 0; i < times.size(); ++i) {
    const double t = times(i);
    while (j + 2 < grid.size() && grid[j + 1] < t) ++j;
    if (t <= grid.front()) {
      out.row(i) = values.front().transpose();
    } else if (t >= grid.back()) {
      out.row(i) = values.back().transpose();
    } else {
      const double w = (t - grid[j]) / (grid[j + 1] - grid[j]);
      out.row(i) = ((1 - w) * values[j] + w * values[j + 1]).transpose();
    }
  }
  return out;
}

}  // namespace

std::vector<std::pair<int, double>> point_weights(const mesh::TetMesh& m,
                                                  const Eigen::Vector3d& p) {
  int best = -1;
  double best_min = -std::numeric_limits<double>::infinity();
  Eigen::Vector4d best_l;
  for (Eigen::Index e = 0; e < m.tets.rows(); ++e) {
    // Cheap rejection by the corners' bounding box.
    Eigen::Vector3d lo = m.nodes.row(m.tets(e, 0)).transpose(), hi = lo;
    for (int k = 1; k < 4; ++k) {
      lo = lo.cwiseMin(m.nodes.row(m.tets(e, k)).transpose());
      hi = hi.cwiseMax(m.nodes.row(m.tets(e, k)).transpose());
    }
    const double pad = 0.5 * (hi - lo).maxCoeff();
    if ((p.array() < lo.array() - pad).any() || (p.array() > hi.array() + pad).any()) continue;
    const Eigen::Vector4d l = barycentric(m, static_cast<int>(e), p);
    if (l.minCoeff() > best_min) {
      best_min = l.minCoeff();
      best = static_cast<int>(e);
      best_l = l;
    }
  }
  if (best < 0)
    throw core::DataError("point (" + std::to_string(p(0)) + ", " + std::to_string(p(1)) + ", " +
                          std::to_string(p(2)) +
                          ") m is not near any element of the mesh: expected a point "
                          "inside the machine; check the data set's positions and length unit (m)");
  Eigen::Vector4d l = best_l.cwiseMax(0.0);
  l /= l.sum();
  std::vector<std::pair<int, double>> w;
  if (m.order == 1) {
    for (int k = 0; k < 4; ++k) w.emplace_back(m.tets(best, k), l(k));
  } else {
    // Quadratic Lagrange weights from the (clamped) barycentric coordinates.
    for (int k = 0; k < 4; ++k) w.emplace_back(m.tets(best, k), l(k) * (2 * l(k) - 1));
    const auto& edges = solvers::kernels::tet_edges;
    for (int k = 0; k < 6; ++k)
      w.emplace_back(m.tets(best, 4 + k), 4 * l(edges[k][0]) * l(edges[k][1]));
  }
  return w;
}

Readout readout(const mesh::TetMesh& m, const core::CaseSpec& spec, const io::MeasuredRun& run) {
  Readout r;
  const Eigen::Index n = m.nodes.rows();
  std::vector<Eigen::Triplet<double>> trip;
  for (size_t s = 0; s < run.sensors.size(); ++s) {
    if (!run.sensors[s].position) continue;
    for (const auto& [node, w] : point_weights(m, *run.sensors[s].position))
      trip.emplace_back(r.sensors, node, w);
    r.ids.push_back(run.sensors[s].id);
    r.run_column.push_back(static_cast<int>(s));
    r.sensors += 1;
  }
  r.temperature.resize(r.sensors, n);
  r.temperature.setFromTriplets(trip.begin(), trip.end());
  std::vector<int> probes;
  for (size_t p = 0; p < run.displacements.size(); ++p)
    if (run.displacements[p].point && run.displacements[p].direction)
      probes.push_back(static_cast<int>(p));
  r.reference_k = spec.mechanical.reference_temperature_c + kCelsius;
  r.displacement.resize(0, n);
  if (!probes.empty() && spec.mechanical.enabled) {
    for (int p : probes) {
      r.ids.push_back(run.displacements[p].id);
      r.run_column.push_back(p);
    }
    r.displacement = displacement_readout(m, spec, run, r);
  }
  if (r.ids.empty())
    throw core::DataError("measured run '" + run.run + "' (" + run.folder.string() +
                          "): no sensor with a position and no probe with a point and direction; "
                          "the model-based calibration needs located channels");
  return r;
}

Eigen::MatrixXd displacement_readout(const mesh::TetMesh& m, const core::CaseSpec& spec,
                                     const io::MeasuredRun& run, const Readout& like) {
  const int probes = like.channels() - like.sensors;
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(probes, m.nodes.rows());
  if (probes == 0) return d;
  const solvers::ElasticModel model(m, spec);
  std::map<std::pair<int, int>, Eigen::VectorXd> cache;  // (node, direction) -> influence
  for (int k = 0; k < probes; ++k) {
    const auto& probe = run.displacements[like.run_column[like.sensors + k]];
    Eigen::Vector3d dir = *probe.direction;
    dir.normalize();
    for (const auto& [node, w] : point_weights(m, *probe.point))
      for (int a = 0; a < 3; ++a) {
        if (dir(a) == 0 || w == 0) continue;
        auto it = cache.find({node, a});
        if (it == cache.end())
          it = cache.emplace(std::make_pair(node, a), model.influence(node, a)).first;
        d.row(k) += (w * dir(a)) * it->second.transpose();
      }
  }
  return d;
}

core::CaseSpec case_for_run(const core::CaseSpec& declared, const io::MeasuredRun& run) {
  const auto it = std::find(run.inputs.begin(), run.inputs.end(), "speed_rpm");
  if (it == run.inputs.end())
    throw core::DataError(
        "measured run '" + run.run + "' (" + run.folder.string() +
        "): no input column 'speed_rpm'; the model needs the spindle speed over time");
  if (run.time.size() < 2)
    throw core::DataError("measured run '" + run.run + "': " + std::to_string(run.time.size()) +
                          " samples; expected at least 2");
  const Eigen::Index col = it - run.inputs.begin();
  core::CaseSpec spec = declared;
  spec.duty_cycle.segments.clear();
  double last = std::nan("");
  for (Eigen::Index i = 0; i < run.time.size(); ++i) {
    double v = run.input_values(i, col);
    if (!std::isfinite(v)) continue;  // a missing speed keeps the previous one
    v = std::max(v, 0.0);
    if (spec.duty_cycle.segments.empty()) {
      spec.duty_cycle.segments.push_back({0.0, v});
      last = v;
    } else if (v != last) {
      spec.duty_cycle.segments.push_back({run.time(i), v});
      last = v;
    }
  }
  if (spec.duty_cycle.segments.empty())
    throw core::DataError("measured run '" + run.run + "': the speed_rpm column has no reading");
  spec.duty_cycle.end = run.time(run.time.size() - 1);
  if (run.initial_temperature_c) spec.thermal.initial_temperature_c = *run.initial_temperature_c;
  spec.thermal.output_interval = spec.thermal.step;
  spec.outputs.fields = false;
  return spec;
}

Eigen::MatrixXd measured_channels(const io::MeasuredRun& run, const Readout& r) {
  Eigen::MatrixXd y(run.time.size(), r.channels());
  for (int c = 0; c < r.channels(); ++c)
    y.col(c) = c < r.sensors ? run.temperature.col(r.run_column[c])
                             : run.displacement.col(r.run_column[c]);
  return y;
}

Responses march(const mesh::TetMesh& m, const core::CaseSpec& spec, const Readout& r,
                const Eigen::VectorXd& times, const std::vector<SeparableColumn>& separable,
                const std::vector<LoadColumn>& loads,
                const std::vector<Eigen::MatrixXd>& extra_displacement) {
  const solvers::FullThermalSystem ops = solvers::thermal_system(m, spec);
  const Eigen::Index n = m.nodes.rows();
  const Eigen::Index ns = static_cast<Eigen::Index>(separable.size());
  const Eigen::Index nc = ns + static_cast<Eigen::Index>(loads.size());
  const double t0_k = spec.thermal.initial_temperature_c + kCelsius;
  Eigen::MatrixXd shapes(n, ns);
  for (Eigen::Index j = 0; j < ns; ++j) shapes.col(j) = separable[j].shape;

  auto read = [&](const Eigen::VectorXd& t, const Eigen::VectorXd& t_start) {
    Eigen::VectorXd y(r.channels());
    if (r.sensors) y.head(r.sensors) = r.temperature * t;
    if (r.displacement.rows()) y.tail(r.displacement.rows()) = r.displacement * (t - t_start);
    return y;
  };
  auto read_block = [&](const Eigen::MatrixXd& x, const Eigen::MatrixXd& x_start) {
    Eigen::MatrixXd y(r.channels(), x.cols());
    if (r.sensors) y.topRows(r.sensors) = r.temperature * x;
    // A coefficient-wise product: a few probe rows do not pay for a blocked, OpenMP-parallel GEMM,
    // whose threads wait on each other every step when the cores are shared.
    if (r.displacement.rows())
      y.bottomRows(r.displacement.rows()) = r.displacement.lazyProduct(x - x_start);
    return y;
  };

  const std::vector<double> steps = solvers::time_grid(spec, spec.thermal.step);
  std::vector<double> grid{0.0};
  grid.insert(grid.end(), steps.begin(), steps.end());
  Eigen::VectorXd temp = Eigen::VectorXd::Constant(n, t0_k);
  const Eigen::VectorXd temp0 = temp;
  Eigen::MatrixXd x = Eigen::MatrixXd::Zero(n, nc);  // responses start from zero
  const Eigen::MatrixXd x0 = x;
  std::vector<Eigen::VectorXd> base_hist{read(temp, temp0)};
  std::vector<Eigen::MatrixXd> col_hist{read_block(x, x0)};
  std::vector<std::vector<Eigen::VectorXd>> extra_hist(extra_displacement.size());
  for (size_t k = 0; k < extra_displacement.size(); ++k)
    extra_hist[k].push_back(Eigen::VectorXd::Zero(extra_displacement[k].rows()));

  std::map<std::pair<double, double>, std::unique_ptr<solvers::cholmod::Factor>> factors;
  double t_prev = 0;
  for (double t : steps) {
    const double dt = t - t_prev, mid = 0.5 * (t + t_prev);
    const double speed = solvers::speed_at(spec.duty_cycle, mid);
    const auto key = std::make_pair(std::round(dt * 1e9) / 1e9, speed);
    auto it = factors.find(key);
    if (it == factors.end()) {
      Eigen::SparseMatrix<double> a = ops.conduction;
      for (size_t c = 0; c < spec.thermal.convection.size(); ++c)
        a += solvers::film_coefficient(spec.thermal.convection[c], speed) * ops.film[c];
      a = ops.capacity + dt * a;
      a.makeCompressed();
      std::ostringstream what;
      what << "calibration march (dt = " << dt << " s, speed = " << speed << " rpm)";
      it = factors.emplace(key, std::make_unique<solvers::cholmod::Factor>(a, what.str())).first;
    }
    // Base step: the declared loads exactly as the thermal solver forms them.
    Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
    for (size_t c = 0; c < spec.thermal.convection.size(); ++c) {
      const auto& cv = spec.thermal.convection[c];
      f += (solvers::film_coefficient(cv, speed) * (solvers::table_value(cv.sink, t) + kCelsius)) *
           ops.film_area[c];
    }
    for (size_t i = 0; i < spec.thermal.sources.size(); ++i) {
      const auto& src = spec.thermal.sources[i];
      double p = solvers::source_power(src, speed);
      if (src.temperature_coefficient != 0)
        p *= 1 + src.temperature_coefficient * (ops.source_shape[i].dot(temp) - t0_k);
      f += p * ops.source_shape[i];
    }
    for (size_t i = 0; i < spec.thermal.fluxes.size(); ++i) {
      const auto& fl = spec.thermal.fluxes[i];
      const double scale = fl.follows_speed ? (speed > 0 ? speed / fl.ref_speed_rpm : 0.0) : 1.0;
      f += fl.flux * scale * ops.flux_area[i];
    }
    Eigen::VectorXd next = ops.capacity * temp + dt * f;
    it->second->solve_in_place(next);
    if (nc > 0) {
      Eigen::MatrixXd rhs = ops.capacity * x;
      for (Eigen::Index j = 0; j < ns; ++j)
        rhs.col(j) += (dt * separable[j].law(t, speed)) * shapes.col(j);
      for (size_t j = 0; j < loads.size(); ++j)
        rhs.col(ns + static_cast<Eigen::Index>(j)) += dt * loads[j].rhs(next, temp, t, speed, dt);
      x = it->second->solve(rhs);
    }
    temp.swap(next);
    base_hist.push_back(read(temp, temp0));
    col_hist.push_back(read_block(x, x0));
    for (size_t k = 0; k < extra_displacement.size(); ++k)
      extra_hist[k].push_back(extra_displacement[k] * (temp - temp0));
    t_prev = t;
  }
  Responses out;
  out.base = sample_at(grid, base_hist, times);
  std::vector<Eigen::VectorXd> one(grid.size());
  for (Eigen::Index j = 0; j < nc; ++j) {
    for (size_t g = 0; g < grid.size(); ++g) one[g] = col_hist[g].col(j);
    out.columns.push_back(sample_at(grid, one, times));
  }
  for (size_t k = 0; k < extra_displacement.size(); ++k) {
    Eigen::MatrixXd e = Eigen::MatrixXd::Zero(times.size(), r.channels());
    e.rightCols(extra_displacement[k].rows()) = sample_at(grid, extra_hist[k], times);
    out.extra.push_back(e);
  }
  return out;
}

Eigen::MatrixXd simulated_channels(const mesh::TetMesh& m, const core::CaseSpec& spec,
                                   const Readout& r, const Eigen::VectorXd& times) {
  core::CaseSpec s = spec;
  s.thermal.output_interval = std::min(s.thermal.output_interval, s.thermal.step);
  const solvers::FullThermalSystem ops = solvers::thermal_system(m, s);
  const solvers::ThermalHistory th = solvers::thermal_history(m, s, ops);
  std::vector<Eigen::VectorXd> hist;
  const Eigen::VectorXd t0 = th.temperature.col(0);
  for (size_t k = 0; k < th.times.size(); ++k) {
    const Eigen::VectorXd t = th.temperature.col(static_cast<Eigen::Index>(k));
    Eigen::VectorXd y(r.channels());
    if (r.sensors) y.head(r.sensors) = r.temperature * t;
    if (r.displacement.rows()) y.tail(r.displacement.rows()) = r.displacement * (t - t0);
    hist.push_back(y);
  }
  return sample_at(th.times, hist, times);
}

}  // namespace tt::calibration
