#include "solvers/thermal.hpp"

#include <cmath>
#include <string>

#include "core/errors.hpp"
#include "core/finite.hpp"
#include "core/parallel.hpp"
#include "solvers/kernels/element.hpp"
#include "solvers/kernels/heat.hpp"
#include "solvers/loads.hpp"
#include "solvers/thermal_stepper.hpp"

namespace tt::solvers {
namespace {

namespace k = kernels;
using Triplets = std::vector<Eigen::Triplet<double>>;

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

/// Conduction and capacity, element by element in parallel chunks.
template <int N>
void volume_operators(const mesh::TetMesh& m, const core::CaseSpec& spec, FullThermalSystem& ops) {
  const int n = static_cast<int>(m.nodes.rows());
  const int nt = static_cast<int>(m.tets.rows());
  constexpr std::ptrdiff_t chunk = 4096;
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
            for (int j = 0; j < N; ++j)
              out.first.emplace_back(m.tets(ti, i), m.tets(ti, j), kc(i, j));
          const double rc = mat.density * mat.specific_heat;
          if (lumped) {
            const auto ml = k::lumped_capacity(x, rc, ti);
            for (int i = 0; i < N; ++i)
              out.second.emplace_back(m.tets(ti, i), m.tets(ti, i), ml(i));
          } else {
            const auto mc = k::capacity_matrix(x, rc, ti);
            for (int i = 0; i < N; ++i)
              for (int j = 0; j < N; ++j)
                out.second.emplace_back(m.tets(ti, i), m.tets(ti, j), mc(i, j));
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
}

/// Each film's unit-coefficient matrix and area vector, each flux's area vector (few faces:
/// serial).
template <int N>
void boundary_operators(const mesh::TetMesh& m, const core::CaseSpec& spec,
                        FullThermalSystem& ops) {
  constexpr int F = N == 4 ? 3 : 6;
  const int n = static_cast<int>(m.nodes.rows());
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
}

/// Each source's load of unit total power spread uniformly over its meshed body.
template <int N>
void source_shapes(const mesh::TetMesh& m, const core::CaseSpec& spec, FullThermalSystem& ops) {
  const int n = static_cast<int>(m.nodes.rows());
  for (const auto& s : spec.thermal.sources) {
    Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
    double volume = 0;
    for (int t = 0; t < m.tets.rows(); ++t) {
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
}

template <int N>
FullThermalSystem assemble(const mesh::TetMesh& m, const core::CaseSpec& spec) {
  check_elements<N>(m);
  FullThermalSystem ops;
  volume_operators<N>(m, spec, ops);
  boundary_operators<N>(m, spec, ops);
  source_shapes<N>(m, spec, ops);
  ops.moving_pieces = moving_source_shapes(m, spec);
  for (const auto& shape : ops.moving_pieces) {
    ops.moving.push_back(moving_load_matrix(shape, m.nodes.rows()));
    ops.moving_source.push_back(shape.source);
  }
  ops.uniform = Eigen::VectorXd::Ones(m.nodes.rows());
  return ops;
}

template <int N>
double stored_heat_total(const mesh::TetMesh& m, const core::CaseSpec& spec,
                         const Eigen::VectorXd& t_k, double t0_k) {
  const int nt = static_cast<int>(m.tets.rows());
  auto parts = core::parallel_chunks<double>(
      nt, 4096, [&](std::ptrdiff_t b, std::ptrdiff_t e, std::ptrdiff_t) {
        double sum = 0;
        for (auto t = b; t < e; ++t) {
          const int ti = static_cast<int>(t);
          const auto& mat = material_of(m, spec, ti);
          Eigen::Matrix<double, N, 1> te;
          for (int a = 0; a < N; ++a) te(a) = t_k(m.tets(ti, a));
          sum +=
              k::stored_heat(tet_coords<N>(m, ti), mat.density * mat.specific_heat, te, t0_k, ti);
        }
        return sum;
      });
  double total = 0;
  for (double p : parts) total += p;
  return total;
}

}  // namespace

double heat_in_law(const core::CaseSpec& spec, const FullThermalSystem& sys) {
  double total = heat_delivered(spec);
  const double end = spec.duty_cycle.end;
  const auto& segs = spec.duty_cycle.segments;
  for (size_t j = 0; j < spec.thermal.fluxes.size(); ++j) {
    const auto& fl = spec.thermal.fluxes[j];
    // Flux-weighted time: n / n_ref over the cycle for a speed-following flux.
    double seconds = end;
    if (fl.follows_speed) {
      seconds = 0;
      for (size_t i = 0; i < segs.size(); ++i) {
        const double b = i + 1 < segs.size() ? segs[i + 1].start : end;
        seconds += segs[i].speed_rpm / fl.ref_speed_rpm * (b - segs[i].start);
      }
    }
    total += fl.flux * sys.flux_area[j].sum() * seconds;
  }
  return total;
}

FullThermalSystem thermal_system(const mesh::TetMesh& mesh, const core::CaseSpec& spec) {
  return mesh.order == 1 ? assemble<4>(mesh, spec) : assemble<10>(mesh, spec);
}

ThermalHistory thermal_history(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                               const FullThermalSystem& system, const Progress& progress,
                               const Checkpointing& checkpointing, const SourceIteration& sources,
                               KeptStepFactors<Eigen::SparseMatrix<double>>* kept) {
  StepperRequest request;
  request.record_times = output_times(spec);
  request.sources = sources;
  SteppedHistory stepped = step_thermal(system, spec, request, progress, checkpointing, kept);
  ThermalHistory hist;
  hist.times = std::move(stepped.times);
  hist.temperature = std::move(stepped.states);
  hist.timings = stepped.timings;
  hist.energy.heat_in = stepped.heat_in;
  hist.energy.lost = stepped.lost;
  hist.energy.stored = stored_heat(mesh, spec, stepped.final_state);
  hist.energy.heat_in_law = heat_in_law(spec, system);
  const std::string origin = "the heat the case puts in over the run overflowed (" +
                             spec.source.string() +
                             "); check thermal.heat_sources power_ref_W and surface_flux flux_W_m2";
  core::require_finite(hist.energy.heat_in, "the heat put in [J]", origin);
  core::require_finite(hist.energy.heat_in_law, "the heat the laws deliver [J]", origin);
  core::require_finite(hist.energy.lost, "the heat lost [J]", origin);
  core::require_finite(hist.energy.stored, "the heat stored [J]", origin);
  return hist;
}

double stored_heat(const mesh::TetMesh& mesh, const core::CaseSpec& spec,
                   const Eigen::VectorXd& temperature) {
  const double t0_k = spec.thermal.initial_temperature_c + core::kCelsiusOffset;
  return mesh.order == 1 ? stored_heat_total<4>(mesh, spec, temperature, t0_k)
                         : stored_heat_total<10>(mesh, spec, temperature, t0_k);
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
  for (int a = 0; a < mesh.nodes_per_tet(); ++a)
    x.col(a) = mesh.nodes.row(mesh.tets(tet, a)).transpose();
  return x;
}

}  // namespace tt::solvers
