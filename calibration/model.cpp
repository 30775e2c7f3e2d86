#include "calibration/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "core/errors.hpp"
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

/// Values at the grid times (#rows x #grid), linearly interpolated at `times` (constant beyond the
/// ends): #times x #rows.
Eigen::MatrixXd sample_at(const std::vector<double>& grid, const Eigen::MatrixXd& values,
                          const Eigen::VectorXd& times) {
  Eigen::MatrixXd out(times.size(), values.rows());
  const Eigen::Index last = values.cols() - 1;
  size_t j = 0;
  for (Eigen::Index i = 0; i < times.size(); ++i) {
    const double t = times(i);
    while (j + 2 < grid.size() && grid[j + 1] < t) ++j;
    const auto c = static_cast<Eigen::Index>(j);
    if (t <= grid.front()) {
      out.row(i) = values.col(0).transpose();
    } else if (t >= grid.back()) {
      out.row(i) = values.col(last).transpose();
    } else {
      const double w = (t - grid[j]) / (grid[j + 1] - grid[j]);
      out.row(i) = ((1 - w) * values.col(c) + w * values.col(c + 1)).transpose();
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
    // The ambient sensor reads the air, not the machine: it gives the air (ambient_reading).
    if (!run.sensors[s].position || run.sensors[s].id == run.ambient_sensor) continue;
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

Eigen::VectorXd ambient_reading(const io::MeasuredRun& run) {
  if (!run.ambient_sensor) return {};
  for (size_t s = 0; s < run.sensors.size(); ++s)
    if (run.sensors[s].id == *run.ambient_sensor)
      return run.temperature.col(static_cast<Eigen::Index>(s));
  throw core::DataError("run '" + run.run + "': ambient_sensor '" + *run.ambient_sensor +
                        "' is not one of its sensors");
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
  const solvers::FullThermalSystem sys = solvers::thermal_system(m, spec);
  solvers::StepperRequest q;
  q.record_times = solvers::time_grid(spec, spec.thermal.step);
  q.record_states = false;
  q.column_readout.sparse = r.temperature;
  q.column_readout.change = r.displacement;
  // The base reads the channels, then every extra readout.
  q.base_readout = q.column_readout;
  Eigen::Index extra_rows = 0;
  for (const auto& e : extra_displacement) extra_rows += e.rows();
  if (extra_rows) {
    Eigen::MatrixXd change(r.displacement.rows() + extra_rows, m.nodes.rows());
    change.topRows(r.displacement.rows()) = r.displacement;
    Eigen::Index at = r.displacement.rows();
    for (const auto& e : extra_displacement) {
      change.middleRows(at, e.rows()) = e;
      at += e.rows();
    }
    q.base_readout.change = std::move(change);
  }
  for (const auto& c : separable) q.shape_columns.push_back({c.shape, c.law});
  for (const auto& c : loads) q.load_columns.push_back(c.rhs);
  const solvers::SteppedHistory h = solvers::step_thermal(sys, spec, q);

  Responses out;
  const Eigen::Index channels = r.channels();
  out.base = sample_at(h.times, h.readout.topRows(channels), times);
  for (const auto& col : h.responses) out.columns.push_back(sample_at(h.times, col, times));
  Eigen::Index at = channels;
  for (const auto& e : extra_displacement) {
    Eigen::MatrixXd x = Eigen::MatrixXd::Zero(times.size(), channels);
    x.rightCols(e.rows()) = sample_at(h.times, h.readout.middleRows(at, e.rows()), times);
    out.extra.push_back(std::move(x));
    at += e.rows();
  }
  return out;
}

Eigen::MatrixXd simulated_channels(const mesh::TetMesh& m, const core::CaseSpec& spec,
                                   const Readout& r, const Eigen::VectorXd& times) {
  core::CaseSpec s = spec;
  s.thermal.output_interval = std::min(s.thermal.output_interval, s.thermal.step);
  const solvers::FullThermalSystem sys = solvers::thermal_system(m, s);
  const solvers::ThermalHistory th = solvers::thermal_history(m, s, sys);
  const Eigen::MatrixXd& t = th.temperature;
  Eigen::MatrixXd y(r.channels(), t.cols());
  if (r.sensors) y.topRows(r.sensors) = r.temperature * t;
  if (r.displacement.rows())
    y.bottomRows(r.displacement.rows()) = r.displacement * (t.colwise() - t.col(0));
  return sample_at(th.times, y, times);
}

}  // namespace tt::calibration
