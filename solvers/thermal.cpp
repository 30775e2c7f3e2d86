#include "solvers/thermal.hpp"

#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <sstream>
#include <string>

#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "solvers/cholmod/cholmod_factor.hpp"
#include "solvers/kernels/element.hpp"
#include "solvers/kernels/heat.hpp"
#include "solvers/loads.hpp"

namespace tt::solvers {
namespace {

namespace k = kernels;
using Triplets = std::vector<Eigen::Triplet<double>>;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

template <int N>
Eigen::Matrix<double, 3, N> tet_coords(const mesh::TetMesh& m, int t) {
  Eigen::Matrix<double, 3, N> x;
  for (int a = 0; a < N; ++a) x.col(a) = m.nodes.row(m.tets(t, a)).transpose();
  return x;
}

template <int N>
Eigen::Matrix<double, 3, N> face_coords(const mesh::TetMesh& m, int f) {
  Eigen::Matrix<double, 3, N> x;
  for (int a = 0; a < N; ++a) x.col(a) = m.nodes.row(m.faces(f, a)).transpose();
  return x;
}

const core::Material& material_of(const mesh::TetMesh& m, const core::CaseSpec& spec, int t) {
  return spec.materials[spec.bodies[core::index_of(m.tet_region[t])].material];
}

/// Serial pass before the parallel loops, so that no exception is thrown inside them.
template <int N>
void check_elements(const mesh::TetMesh& m) {
  for (int t = 0; t < m.tets.rows(); ++t)
    if (!(k::min_jacobian_determinant(tet_coords<N>(m, t)) > 0))
      throw core::SolverError("element " + std::to_string(t) +
                              " is inverted or degenerate (det J <= 0). Hint: remesh.");
}

Eigen::SparseMatrix<double> to_sparse(int n, const std::vector<Triplets>& chunks) {
  size_t total = 0;
  for (const auto& c : chunks) total += c.size();
  Triplets all;
  all.reserve(total);
  for (const auto& c : chunks) all.insert(all.end(), c.begin(), c.end());
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(all.begin(), all.end());
  a.makeCompressed();
  return a;
}

template <int N>
FullThermalSystem assemble(const mesh::TetMesh& m, const core::CaseSpec& spec) {
  constexpr int F = N == 4 ? 3 : 6;
  check_elements<N>(m);
  const int n = static_cast<int>(m.nodes.rows());
  const int nt = static_cast<int>(m.tets.rows());
  constexpr std::ptrdiff_t chunk = 4096;
  FullThermalSystem ops;
  const bool lumped = spec.thermal.lumped_mass;
  auto pairs = core::parallel_chunks<std::pair<Triplets, Triplets>>(
      nt, chunk, [&](std::ptrdiff_t b, std::ptrdiff_t e, std::ptrdiff_t) {
        std::pair<Triplets, Triplets> out;
        out.first.reserve((e - b) * N * N);
        out.second.reserve((e - b) * N * (lumped ? 1 : N));
        for (auto t = b; t < e; ++t) {
          const int ti = static_cast<int>(t);
          const auto x = tet_coords<N>(m, ti);
          const auto& mat = material_of(m, spec, ti);
          const auto kc = k::conductivity_matrix(x, mat.conductivity, ti);
          for (int i = 0; i < N; ++i)
            for (int j = 0; j < N; ++j) out.first.emplace_back(m.tets(ti, i), m.tets(ti, j), kc(i, j));
          const double rc = mat.density * mat.specific_heat;
          if (lumped) {
            const auto ml = k::lumped_capacity(x, rc, ti);
            for (int i = 0; i < N; ++i) out.second.emplace_back(m.tets(ti, i), m.tets(ti, i), ml(i));
          } else {
            const auto mc = k::capacity_matrix(x, rc, ti);
            for (int i = 0; i < N; ++i)
              for (int j = 0; j < N; ++j) out.second.emplace_back(m.tets(ti, i), m.tets(ti, j), mc(i, j));
          }
        }
        return out;
      });
  std::vector<Triplets> kt, mt;
  for (auto& p : pairs) {
    kt.push_back(std::move(p.first));
    mt.push_back(std::move(p.second));
  }
  ops.conduction = to_sparse(n, kt);
  ops.capacity = to_sparse(n, mt);

  // Convection and flux on boundary groups (few faces: serial).
  for (const auto& c : spec.thermal.convection) {
    Triplets h;
    Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
    for (int f = 0; f < m.faces.rows(); ++f) {
      if (core::index_of(m.face_group[f]) != c.group) continue;
      const auto x = face_coords<F>(m, f);
      const auto hm = k::convection_matrix(x, 1.0, f);
      const auto hl = k::convection_load(x, 1.0, 1.0, f);
      for (int i = 0; i < F; ++i) {
        w(m.faces(f, i)) += hl(i);
        for (int j = 0; j < F; ++j) h.emplace_back(m.faces(f, i), m.faces(f, j), hm(i, j));
      }
    }
    ops.film.push_back(to_sparse(n, {h}));
    ops.film_area.push_back(std::move(w));
  }
  for (const auto& fl : spec.thermal.fluxes) {
    Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
    for (int f = 0; f < m.faces.rows(); ++f) {
      if (core::index_of(m.face_group[f]) != fl.group) continue;
      const auto load = k::flux_load(face_coords<F>(m, f), 1.0, f);
      for (int i = 0; i < F; ++i) w(m.faces(f, i)) += load(i);
    }
    ops.flux_area.push_back(std::move(w));
  }
  // Sources: unit total power spread uniformly over the meshed body.
  for (const auto& s : spec.thermal.sources) {
    Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
    double volume = 0;
    for (int t = 0; t < nt; ++t) {
      if (core::index_of(m.tet_region[t]) != s.body) continue;
      const auto x = tet_coords<N>(m, t);
      volume += k::element_volume(x, t);
      const auto q = k::source_vector(x, 1.0, t);
      for (int i = 0; i < N; ++i) w(m.tets(t, i)) += q(i);
    }
    if (!(volume > 0))
      throw core::SolverError("thermal.heat_sources '" + s.name + "': body '" +
                              spec.bodies[s.body].name +
                              "' has no elements, so its heat cannot go anywhere");
    ops.source_shape.push_back(w / volume);
  }
  ops.moving_pieces = moving_source_shapes(m, spec);
  for (const auto& shape : ops.moving_pieces) {
    ops.moving.push_back(moving_load_matrix(shape, n));
    ops.moving_source.push_back(shape.source);
  }
  ops.uniform = Eigen::VectorXd::Ones(n);
  return ops;
}

template <int N>
double stored_heat_total(const mesh::TetMesh& m, const core::CaseSpec& spec, const Eigen::VectorXd& t_k,
                         double t0_k) {
  const int nt = static_cast<int>(m.tets.rows());
  auto parts = core::parallel_chunks<double>(nt, 4096, [&](std::ptrdiff_t b, std::ptrdiff_t e, std::ptrdiff_t) {
    double sum = 0;
    for (auto t = b; t < e; ++t) {
      const int ti = static_cast<int>(t);
      const auto& mat = material_of(m, spec, ti);
      Eigen::Matrix<double, N, 1> te;
      for (int a = 0; a < N; ++a) te(a) = t_k(m.tets(ti, a));
      sum += k::stored_heat(tet_coords<N>(m, ti), mat.density * mat.specific_heat, te, t0_k, ti);
    }
    return sum;
  });
  double total = 0;
  for (double p : parts) total += p;
  return total;
}

/// Heat rate leaving through every convection entry [W]: h (int T dA - T_sink int dA), with
/// int T dA from the face-quadrature weights (exact for the element's T).
double convected_rate(const FullThermalSystem& ops, const Eigen::VectorXd& t_k, const std::vector<double>& h,
                      const std::vector<double>& sink_k) {
  double rate = 0;
  for (size_t c = 0; c < h.size(); ++c)
    rate += h[c] * (ops.film_area[c].dot(t_k) - sink_k[c] * ops.film_area[c].sum());
  return rate;
}

/// The loads at one instant: matrix key (speed), film coefficients, sinks, source powers.
struct LoadState {
  double speed = 0;
  std::vector<double> h, sink_k, power;
};

LoadState load_state(const core::CaseSpec& spec, const FullThermalSystem& ops, double t_load,
                     double t_sink, const Eigen::VectorXd& temperature, double t0_k) {
  LoadState s;
  s.speed = speed_at(spec.duty_cycle, t_load);
  for (const auto& c : spec.thermal.convection) {
    s.h.push_back(film_coefficient(c, s.speed));
    s.sink_k.push_back(table_value(c.sink, t_sink) + kCelsiusOffset);
  }
  for (size_t i = 0; i < spec.thermal.sources.size(); ++i) {
    const auto& src = spec.thermal.sources[i];
    // Moving sources enter through moving_heat_load, not through source_shape.
    const double feed = feed_speed_at(spec.feed_axis, t_load);
    double p = src.window > 0 ? 0.0 : source_power(src, s.speed, feed);
    if (src.temperature_coefficient != 0)
      p *= 1 + src.temperature_coefficient * (ops.source_shape[i].dot(temperature) - t0_k);
    s.power.push_back(p);
  }
  return s;
}

Eigen::VectorXd load_vector(const core::CaseSpec& spec, const FullThermalSystem& ops, const LoadState& s) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(ops.conduction.rows());
  for (size_t c = 0; c < s.h.size(); ++c) f += (s.h[c] * s.sink_k[c]) * ops.film_area[c];
  for (size_t i = 0; i < s.power.size(); ++i) f += s.power[i] * ops.source_shape[i];
  for (size_t i = 0; i < spec.thermal.fluxes.size(); ++i) {
    const auto& fl = spec.thermal.fluxes[i];
    const double scale = fl.follows_speed ? (s.speed > 0 ? s.speed / fl.ref_speed_rpm : 0.0) : 1.0;
    f += fl.flux * scale * ops.flux_area[i];
  }
  return f;
}

/// Checks that a saved state belongs to this mesh and time grid before the loop trusts it.
void check_resume(const ThermalCheckpoint& c, int nodes, const std::vector<double>& grid, size_t times) {
  const auto fail = [](const std::string& what) {
    throw core::SolverError("checkpoint does not fit this run: " + what +
                            "; remove the checkpoint or run without --resume");
  };
  if (c.temperature.size() != nodes || c.outputs.rows() != nodes)
    fail("it has " + std::to_string(c.temperature.size()) + " nodes, the mesh " + std::to_string(nodes));
  if (c.steps < 1 || static_cast<size_t>(c.steps) >= grid.size() || grid[c.steps - 1] != c.time)
    fail("step " + std::to_string(c.steps) + " at t = " + std::to_string(c.time) +
         " s is not an inner step of the time grid (" + std::to_string(grid.size()) + " steps)");
  if (c.outputs.cols() < 1 || static_cast<size_t>(c.outputs.cols()) > times)
    fail(std::to_string(c.outputs.cols()) + " output columns, at most " + std::to_string(times) + " expected");
}

template <int N>
ThermalHistory integrate(const mesh::TetMesh& m, const core::CaseSpec& spec, const FullThermalSystem& ops,
                         const Progress& progress, const Checkpointing& checkpointing) {
  using Scheme = core::TimeScheme;
  const Scheme scheme = spec.thermal.scheme;
  if (scheme == Scheme::bdf2)
    throw core::SolverError("thermal.scheme = \"bdf2\" is not implemented: use \"backward_euler\" "
                            "or \"crank_nicolson\"");
  const int n = static_cast<int>(m.nodes.rows());
  const double t0_k = spec.thermal.initial_temperature_c + kCelsiusOffset;
  const double end = spec.duty_cycle.end;
  const std::vector<double> grid = time_grid(spec, spec.thermal.step);
  const std::vector<double> outs = output_times(spec);

  ThermalHistory hist;
  hist.times.push_back(0.0);
  hist.times.insert(hist.times.end(), outs.begin(), outs.end());
  hist.temperature.resize(n, static_cast<Eigen::Index>(hist.times.size()));
  Eigen::VectorXd temp = Eigen::VectorXd::Constant(n, t0_k);
  hist.temperature.col(0) = temp;
  size_t next_out = 1;

  // Stiffness per speed and factors per (step, speed, scheme weight): built on first use.
  std::map<double, Eigen::SparseMatrix<double>> stiffness;
  std::map<std::tuple<double, double, double>, std::unique_ptr<cholmod::Factor>> factors;
  auto stiffness_at = [&](const LoadState& s) -> const Eigen::SparseMatrix<double>& {
    auto it = stiffness.find(s.speed);
    if (it != stiffness.end()) return it->second;
    Eigen::SparseMatrix<double> kk = ops.conduction;
    for (size_t c = 0; c < s.h.size(); ++c) kk += s.h[c] * ops.film[c];
    kk.makeCompressed();
    return stiffness.emplace(s.speed, std::move(kk)).first->second;
  };
  auto factor_for = [&](double dt, double theta, const LoadState& s) -> const cholmod::Factor& {
    const auto key = std::make_tuple(std::round(dt * 1e9) / 1e9, s.speed, theta);
    auto it = factors.find(key);
    if (it != factors.end()) return *it->second;
    const auto t_f = Clock::now();
    Eigen::SparseMatrix<double> a = ops.capacity + (theta * dt) * stiffness_at(s);
    a.makeCompressed();
    std::ostringstream what;
    what << "thermal system (dt = " << dt << " s, speed = " << s.speed << " rpm)";
    auto f = std::make_unique<cholmod::Factor>(a, what.str());
    hist.timings.factor_s += seconds_since(t_f);
    hist.timings.factorizations += 1;
    hist.timings.factor_entries = std::max(hist.timings.factor_entries, f->factor_entries());
    return *factors.emplace(key, std::move(f)).first->second;
  };

  const auto t_solve = Clock::now();
  double t_prev = 0, prev_speed = std::nan("");
  double lost_rate_prev = 0;  // heat rate out at t_prev under the current interval's h (CN)
  size_t first_step = 0;
  if (const ThermalCheckpoint* c = checkpointing.resume) {
    check_resume(*c, n, grid, hist.times.size());
    first_step = static_cast<size_t>(c->steps);
    t_prev = c->time;
    prev_speed = c->speed;
    temp = c->temperature;
    next_out = static_cast<size_t>(c->outputs.cols());
    hist.temperature.leftCols(c->outputs.cols()) = c->outputs;
    hist.energy.heat_in = c->heat_in;
    hist.energy.lost = c->lost;
    hist.timings.steps = c->steps;
  }
  auto t_saved = Clock::now();
  Eigen::VectorXd rhs(n), f_prev, f_new;
  for (size_t i = first_step; i < grid.size(); ++i) {
    const double t = grid[i], dt = t - t_prev, mid = 0.5 * (t_prev + t);
    const LoadState s_new = load_state(spec, ops, mid, t, temp, t0_k);
    // Crank–Nicolson restarts with one backward-Euler step after every load discontinuity.
    const bool restart = i == 0 || s_new.speed != prev_speed;
    const bool cn = scheme == Scheme::crank_nicolson && !restart;
    const Eigen::SparseMatrix<double>& kk = stiffness_at(s_new);
    // Heat moving with the feed axis: averaged over the step, the same for both ends of CN.
    const Eigen::VectorXd f_moving = moving_heat_load(spec, ops.moving_pieces, n, t_prev, t);
    f_new = load_vector(spec, ops, s_new) + f_moving;
    if (cn) {
      const LoadState s_old = load_state(spec, ops, mid, t_prev, temp, t0_k);
      f_prev = load_vector(spec, ops, s_old) + f_moving;
      rhs = ops.capacity * temp - (0.5 * dt) * (kk * temp) + (0.5 * dt) * (f_prev + f_new);
      lost_rate_prev = convected_rate(ops, temp, s_old.h, s_old.sink_k);
    } else {
      rhs = ops.capacity * temp + dt * f_new;
    }
    const cholmod::Factor& factor = factor_for(dt, cn ? 0.5 : 1.0, s_new);
    Eigen::VectorXd next = rhs;
    factor.solve_in_place(next);

    double power = 0;
    for (double p : s_new.power) power += p;
    const double lost_new = convected_rate(ops, next, s_new.h, s_new.sink_k);
    hist.energy.heat_in += dt * (power + f_moving.sum());
    hist.energy.lost += cn ? 0.5 * dt * (lost_rate_prev + lost_new) : dt * lost_new;
    // Surface fluxes enter as heat too.
    for (size_t j = 0; j < spec.thermal.fluxes.size(); ++j) {
      const auto& fl = spec.thermal.fluxes[j];
      const double scale = fl.follows_speed ? (s_new.speed > 0 ? s_new.speed / fl.ref_speed_rpm : 0.0) : 1.0;
      hist.energy.heat_in += dt * fl.flux * scale * ops.flux_area[j].sum();
    }

    while (next_out < hist.times.size() && hist.times[next_out] <= t + 1e-9 * end) {
      const double w = (hist.times[next_out] - t_prev) / dt;
      hist.temperature.col(static_cast<Eigen::Index>(next_out)) = (1 - w) * temp + w * next;
      ++next_out;
    }
    temp.swap(next);
    t_prev = t;
    prev_speed = s_new.speed;
    hist.timings.steps += 1;
    if (progress) progress(t, end);
    if (checkpointing.save && i + 1 < grid.size() && seconds_since(t_saved) >= checkpointing.interval_s) {
      const auto cols = static_cast<Eigen::Index>(next_out);
      checkpointing.save({static_cast<int>(i + 1), t, prev_speed, temp, hist.temperature.leftCols(cols),
                          hist.energy.heat_in, hist.energy.lost});
      t_saved = Clock::now();
    }
  }
  hist.timings.solve_s = seconds_since(t_solve) - hist.timings.factor_s;
  hist.energy.stored = stored_heat_total<N>(m, spec, temp, t0_k);
  hist.energy.heat_in_law = heat_delivered(spec);
  const auto& segs = spec.duty_cycle.segments;
  for (size_t j = 0; j < spec.thermal.fluxes.size(); ++j) {
    const auto& fl = spec.thermal.fluxes[j];
    double seconds = end;  // flux-weighted time: n / n_ref over the cycle for a speed-following flux
    if (fl.follows_speed) {
      seconds = 0;
      for (size_t i = 0; i < segs.size(); ++i) {
        const double b = i + 1 < segs.size() ? segs[i + 1].start : end;
        seconds += segs[i].speed_rpm / fl.ref_speed_rpm * (b - segs[i].start);
      }
    }
    hist.energy.heat_in_law += fl.flux * ops.flux_area[j].sum() * seconds;
  }
  return hist;
}

}  // namespace

FullThermalSystem thermal_system(const mesh::TetMesh& mesh, const core::CaseSpec& spec) {
  return mesh.order == 1 ? assemble<4>(mesh, spec) : assemble<10>(mesh, spec);
}

ThermalHistory thermal_history(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                               const FullThermalSystem& ops, const Progress& progress,
                               const Checkpointing& checkpointing) {
  return mesh.order == 1 ? integrate<4>(mesh, spec, ops, progress, checkpointing)
                         : integrate<10>(mesh, spec, ops, progress, checkpointing);
}

Eigen::MatrixXd nodal_history(const ThermalHistory& history, const std::vector<int>& nodes) {
  const Eigen::MatrixXd& t = history.temperature;
  Eigen::MatrixXd out(t.cols(), static_cast<Eigen::Index>(nodes.size()));
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i] < 0 || nodes[i] >= t.rows())
      throw core::SolverError("node " + std::to_string(nodes[i]) +
                              " asked for a history: the mesh has " + std::to_string(t.rows()) +
                              " nodes");
    out.col(static_cast<Eigen::Index>(i)) = t.row(nodes[i]).transpose();
  }
  return out;
}

Eigen::Matrix<double, 3, Eigen::Dynamic> element_coordinates(const mesh::TetMesh& mesh, int tet) {
  Eigen::Matrix<double, 3, Eigen::Dynamic> x(3, mesh.nodes_per_tet());
  for (int a = 0; a < mesh.nodes_per_tet(); ++a) x.col(a) = mesh.nodes.row(mesh.tets(tet, a)).transpose();
  return x;
}

}  // namespace tt::solvers
