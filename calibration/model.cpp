#include "calibration/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <type_traits>
#include <variant>

#include "core/errors.hpp"
#include "solvers/elastic.hpp"
#include "solvers/kernels/element.hpp"
#include "solvers/loads.hpp"
#include "solvers/thermal.hpp"

namespace tt::calibration {

namespace {

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

Readout temperature_readout(const mesh::TetMesh& m, const core::CaseSpec& spec,
                            const std::vector<std::string>& ids,
                            const std::vector<Eigen::Vector3d>& points) {
  if (ids.size() != points.size())
    throw core::DataError("readout: " + std::to_string(ids.size()) + " sensor ids and " +
                          std::to_string(points.size()) + " points: expected one point per id");
  Readout r;
  std::vector<Eigen::Triplet<double>> trip;
  for (size_t s = 0; s < ids.size(); ++s)
    for (const auto& [node, w] : point_weights(m, points[s]))
      trip.emplace_back(static_cast<int>(s), node, w);
  r.ids = ids;
  r.sensors = static_cast<int>(ids.size());
  r.run_column.resize(ids.size());
  std::iota(r.run_column.begin(), r.run_column.end(), 0);
  r.temperature.resize(r.sensors, m.nodes.rows());
  r.temperature.setFromTriplets(trip.begin(), trip.end());
  r.reference_k = spec.mechanical.reference_temperature_c + core::kCelsiusOffset;
  r.displacement.resize(0, m.nodes.rows());
  return r;
}

namespace {

/// The located channels of `run`: sensors with their weights, probes with their geometry; no
/// displacement rows yet.
Readout located(const mesh::TetMesh& m, const core::CaseSpec& spec, const io::MeasuredRun& run) {
  std::vector<std::string> ids;
  std::vector<Eigen::Vector3d> points;
  std::vector<int> columns;
  for (size_t s = 0; s < run.sensors.size(); ++s) {
    // The ambient sensor reads the air, not the machine: it gives the air (ambient_reading).
    if (!run.sensors[s].position || run.sensors[s].id == run.ambient_sensor) continue;
    ids.push_back(run.sensors[s].id);
    points.push_back(*run.sensors[s].position);
    columns.push_back(static_cast<int>(s));
  }
  Readout r = temperature_readout(m, spec, ids, points);
  r.run_column = columns;
  std::vector<int> probes;
  for (size_t p = 0; p < run.displacements.size(); ++p)
    if (run.displacements[p].point && run.displacements[p].direction)
      probes.push_back(static_cast<int>(p));
  if (!probes.empty() && spec.mechanical.enabled) {
    for (int p : probes) {
      r.ids.push_back(run.displacements[p].id);
      r.run_column.push_back(p);
      r.probe_point.push_back(*run.displacements[p].point);
      r.probe_direction.push_back(run.displacements[p].direction->normalized());
    }
  }
  if (r.ids.empty())
    throw core::DataError("measured run '" + run.run + "' (" + run.folder.string() +
                          "): no sensor with a position and no probe with a point and direction; "
                          "the model-based calibration needs located channels");
  return r;
}

/// The probes' influence rows (r.displacement) and their parts per material (r.expansion): one
/// elastic factor, one block solve for all probes.
void add_displacement_rows(const mesh::TetMesh& m, const core::CaseSpec& spec, Readout& r) {
  if (r.probe_point.empty()) return;
  std::vector<Eigen::Triplet<double>> trip;
  for (size_t k = 0; k < r.probe_point.size(); ++k)
    for (const auto& [node, w] : point_weights(m, r.probe_point[k]))
      for (int a = 0; a < 3; ++a)
        if (w != 0 && r.probe_direction[k](a) != 0)
          trip.emplace_back(static_cast<int>(k), 3 * node + a, w * r.probe_direction[k](a));
  Eigen::SparseMatrix<double> f(static_cast<Eigen::Index>(r.probe_point.size()),
                                3 * m.nodes.rows());
  f.setFromTriplets(trip.begin(), trip.end());
  const solvers::ElasticModel model(m, spec);
  r.expansion = model.influence_rows_by_material(f, m, spec);
  r.displacement = Eigen::MatrixXd::Zero(f.rows(), m.nodes.rows());
  for (const auto& part : r.expansion) r.displacement += part;
}

}  // namespace

Readout readout(const mesh::TetMesh& m, const core::CaseSpec& spec, const io::MeasuredRun& run) {
  Readout r = located(m, spec, run);
  add_displacement_rows(m, spec, r);
  return r;
}

Readout readout_like(const mesh::TetMesh& m, const core::CaseSpec& spec, const io::MeasuredRun& run,
                     const Readout& like) {
  Readout r = located(m, spec, run);
  if (r.probe_point.empty()) return r;
  const bool same = r.probe_point == like.probe_point &&
                    r.probe_direction == like.probe_direction &&
                    like.displacement.rows() == static_cast<Eigen::Index>(r.probe_point.size()) &&
                    like.displacement.cols() == m.nodes.rows();
  if (same) {
    r.displacement = like.displacement;
    r.expansion = like.expansion;
  } else {
    add_displacement_rows(m, spec, r);
  }
  return r;
}

Eigen::MatrixXd displacement_with_expansions(const Readout& like, const core::CaseSpec& declared,
                                             const core::CaseSpec& spec) {
  Eigen::MatrixXd d = like.displacement;
  for (size_t k = 0; k < like.expansion.size() && k < spec.materials.size(); ++k) {
    const double a0 = declared.materials[k].expansion, a1 = spec.materials[k].expansion;
    if (a1 != a0) d += ((a1 - a0) / a0) * like.expansion[k];
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
  try {
    solvers::check_first_sample_time(run.time(0), declared.thermal.step);
  } catch (const core::DataError& e) {
    throw core::DataError("measured run '" + run.run + "' (" + (run.folder / "data.csv").string() +
                          "): " + e.what());
  }
  const Eigen::Index col = it - run.inputs.begin();
  core::CaseSpec spec = declared;
  spec.duty_cycle.segments.clear();
  // Sample by sample, as a live stream is read (solvers::LiveObserver).
  for (Eigen::Index i = 0; i < run.time.size(); ++i)
    solvers::extend_duty_cycle(spec.duty_cycle, run.time(i), run.input_values(i, col));
  if (spec.duty_cycle.segments.empty())
    throw core::DataError("measured run '" + run.run + "': the speed_rpm column has no reading");
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

MarchModel::MarchModel(const mesh::TetMesh& mesh, const core::CaseSpec& spec)
    : mesh_(&mesh),
      full_(
          std::make_shared<const solvers::FullThermalSystem>(solvers::thermal_system(mesh, spec))) {
}

MarchModel::MarchModel(const mesh::TetMesh& mesh, const core::CaseSpec& spec, const Readout& r,
                       solvers::ReductionOptions options)
    : MarchModel(mesh, spec) {
  const Eigen::Index n = mesh.nodes.rows();
  Eigen::MatrixXd rows(r.temperature.rows() + r.displacement.rows(), n);
  rows.topRows(r.temperature.rows()) = Eigen::MatrixXd(r.temperature);
  rows.bottomRows(r.displacement.rows()) = r.displacement;
  options.output_columns = rows.transpose();
  reduced_ =
      std::make_shared<const solvers::ReducedModel>(solvers::reduced_model(*full_, spec, options));
  system_ = std::shared_ptr<const solvers::ReducedThermalSystem>(reduced_, &reduced_->system);
}

MarchModel MarchModel::with_case(const mesh::TetMesh& mesh, const core::CaseSpec& other) const {
  if (mesh.nodes.rows() != mesh_->nodes.rows())
    throw core::SolverError("calibration: a case meshed with " + std::to_string(mesh.nodes.rows()) +
                            " nodes cannot use a model of " + std::to_string(mesh_->nodes.rows()) +
                            " nodes");
  MarchModel m(mesh, other);
  if (reduced_) {
    m.reduced_ = reduced_;
    m.system_ = std::make_shared<const solvers::ReducedThermalSystem>(
        solvers::projected_system(*m.full_, reduced_->basis));
  }
  return m;
}

Eigen::MatrixXd MarchModel::projected(const Eigen::SparseMatrix<double>& a) const {
  if (!reduced_) throw core::SolverError("calibration: projected operator of a full-order model");
  const Eigen::MatrixXd av = a * reduced_->basis;
  const Eigen::MatrixXd p = reduced_->basis.transpose() * av;
  return 0.5 * (p + p.transpose());
}

int MarchModel::order() const {
  return reduced_ ? reduced_->states() : static_cast<int>(full_->states());
}

namespace {

/// A load's weighted load over a step from its load at one end, `at(base state, time)`: the
/// end's for backward Euler, theta-weighted over both ends for Crank–Nicolson.
template <class AtEnd>
Eigen::VectorXd at_step_ends(const solvers::StepView& step, const AtEnd& at) {
  if (step.theta == 1) return at(*step.state1, step.t1);
  return step.theta * at(*step.state1, step.t1) + (1 - step.theta) * at(*step.state0, step.t0);
}

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

/// The step load of `form` on `ops` (the full system, or the reduced one with the same entries).
/// `spec` gives the films' laws and sinks and the sources' powers; its lifetime must cover the
/// march.
template <class Matrix>
solvers::LoadCallback load_callback(const solvers::LinearThermalSystem<Matrix>& ops,
                                    const core::CaseSpec& spec, const LoadForm& form) {
  constexpr bool reduced = std::is_same_v<Matrix, Eigen::MatrixXd>;
  const auto& conv = spec.thermal.convection;
  return std::visit(
      Overloaded{
          [&](const SinkHat& f) -> solvers::LoadCallback {
            return [&ops, &conv, f](const solvers::StepView& step) {
              return at_step_ends(step, [&](const Eigen::VectorXd&, double t) {
                const double hat = std::max(0.0, 1 - std::abs(t - f.knot_s) / f.width_s);
                Eigen::VectorXd b = Eigen::VectorXd::Zero(ops.states());
                if (hat == 0) return b;
                for (int e : f.entries)
                  b += (hat * solvers::film_coefficient(conv[e], step.speed)) * ops.film_area[e];
                return b;
              });
            };
          },
          [&](const FilmChange& f) -> solvers::LoadCallback {
            return [&ops, &conv, f](const solvers::StepView& step) {
              const double scale =
                  f.follows_speed
                      ? (step.speed > 0 ? std::pow(step.speed / f.ref_speed_rpm, f.speed_exponent)
                                        : 0.0)
                      : 1.0;
              if (scale == 0) return Eigen::VectorXd::Zero(ops.states()).eval();
              const auto& c = conv[f.entry];
              return at_step_ends(step, [&](const Eigen::VectorXd& temp, double t) {
                const double sink = solvers::table_value(c.sink, t) + core::kCelsiusOffset;
                return Eigen::VectorXd(-scale *
                                       (ops.film[f.entry] * temp - sink * ops.film_area[f.entry]));
              });
            };
          },
          [&](const SourceGrowth& f) -> solvers::LoadCallback {
            return [&ops, &spec, f](const solvers::StepView& step) {
              // The source's heat over the step as the stepper forms it (feed at the middle).
              const double feed = solvers::feed_speed_at(spec.feed_axis, 0.5 * (step.t0 + step.t1));
              const auto& src = spec.thermal.sources[static_cast<size_t>(f.source)];
              const double q = solvers::source_power(src, step.speed, feed);
              const Eigen::VectorXd& shape = ops.source_shape[static_cast<size_t>(f.source)];
              return at_step_ends(step, [&](const Eigen::VectorXd& temp, double) {
                return Eigen::VectorXd(q * (shape.dot(temp) - f.reference_k) * shape);
              });
            };
          },
          [&](const OperatorChange& f) -> solvers::LoadCallback {
            std::shared_ptr<const Matrix> a;
            if constexpr (reduced)
              a = f.reduced;
            else
              a = f.full;
            if (!a)
              throw core::SolverError("calibration: an operator change without its " +
                                      std::string(reduced ? "projected" : "full") + " operator");
            if (f.which == OperatorChange::Operator::conduction)
              return [a](const solvers::StepView& step) {
                return at_step_ends(step, [&](const Eigen::VectorXd& temp, double) {
                  return Eigen::VectorXd(-(*a * temp));
                });
              };
            // dC (T1 - T0) / dt under either scheme.
            return [a](const solvers::StepView& step) {
              return Eigen::VectorXd(-(*a * (*step.state1 - *step.state0)) / step.dt());
            };
          },
          [&](const solvers::LoadCallback& f) -> solvers::LoadCallback {
            if (reduced)
              throw core::SolverError(
                  "calibration: a load given as a callback on the full system cannot be marched "
                  "on the reduced model; use the full order");
            return f;
          }},
      form);
}

/// The march on one system: `read` the channels' rows on its states (the base reads them and
/// `extra` after), `shapes` the separable columns' shapes on its states.
template <class Matrix>
Responses march_on(const solvers::LinearThermalSystem<Matrix>& sys, const core::CaseSpec& spec,
                   const solvers::StateReadout& read, Eigen::Index channels,
                   const std::vector<Eigen::MatrixXd>& extra, const Eigen::VectorXd& times,
                   const std::vector<SeparableColumn>& separable,
                   const std::vector<Eigen::VectorXd>& shapes,
                   const std::vector<LoadColumn>& loads) {
  solvers::StepperRequest q;
  q.record_times = solvers::time_grid(spec, spec.thermal.step);
  q.record_states = false;
  q.column_readout = read;
  q.base_readout = read;
  Eigen::Index extra_rows = 0;
  for (const auto& e : extra) extra_rows += e.rows();
  if (extra_rows) {
    Eigen::MatrixXd change(read.change.rows() + extra_rows, read.change.cols());
    change.topRows(read.change.rows()) = read.change;
    Eigen::Index at = read.change.rows();
    for (const auto& e : extra) {
      change.middleRows(at, e.rows()) = e;
      at += e.rows();
    }
    q.base_readout.change = std::move(change);
  }
  for (size_t k = 0; k < separable.size(); ++k)
    q.shape_columns.push_back({shapes[k], separable[k].law});
  for (const auto& c : loads) q.load_columns.push_back(load_callback(sys, spec, c.form));
  const solvers::SteppedHistory h = solvers::step_thermal(sys, spec, q);

  Responses out;
  out.base = sample_at(h.times, h.readout.topRows(channels), times);
  for (const auto& col : h.responses) out.columns.push_back(sample_at(h.times, col, times));
  Eigen::Index at = channels;
  for (const auto& e : extra) {
    Eigen::MatrixXd x = Eigen::MatrixXd::Zero(times.size(), channels);
    x.rightCols(e.rows()) = sample_at(h.times, h.readout.middleRows(at, e.rows()), times);
    out.extra.push_back(std::move(x));
    at += e.rows();
  }
  return out;
}

}  // namespace

Responses march(const MarchModel& model, const core::CaseSpec& spec, const Readout& r,
                const Eigen::VectorXd& times, const std::vector<SeparableColumn>& separable,
                const std::vector<LoadColumn>& loads,
                const std::vector<Eigen::MatrixXd>& extra_displacement) {
  if (!model.is_reduced()) {
    solvers::StateReadout read;
    read.sparse = r.temperature;
    read.change = r.displacement;
    std::vector<Eigen::VectorXd> shapes;
    for (const auto& c : separable) shapes.push_back(c.shape);
    return march_on(model.full(), spec, read, r.channels(), extra_displacement, times, separable,
                    shapes, loads);
  }
  // Reduced: the rows and shapes on the basis, T = V z.
  const Eigen::MatrixXd& v = model.reduced()->basis;
  solvers::StateReadout read;
  read.dense = r.temperature * v;
  read.change = r.displacement * v;
  std::vector<Eigen::MatrixXd> extra;
  for (const auto& e : extra_displacement) extra.push_back(e * v);
  std::vector<Eigen::VectorXd> shapes;
  for (const auto& c : separable) shapes.push_back(v.transpose() * c.shape);
  return march_on(model.reduced_system(), spec, read, r.channels(), extra, times, separable, shapes,
                  loads);
}

Responses march(const mesh::TetMesh& m, const core::CaseSpec& spec, const Readout& r,
                const Eigen::VectorXd& times, const std::vector<SeparableColumn>& separable,
                const std::vector<LoadColumn>& loads,
                const std::vector<Eigen::MatrixXd>& extra_displacement) {
  return march(MarchModel(m, spec), spec, r, times, separable, loads, extra_displacement);
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
