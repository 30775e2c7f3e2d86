// Reduced-order model against the full one: order, build time, accuracy and run time of the
// reduced model on duty cycles its basis was not built from, for several bases: block rational
// Krylov with the default shifts, with fewer and more shifts, with a second moment, and snapshot
// POD from one full run of the case's own duty cycle (the alternative docs/reduced-order.md
// weighs).
//
// Run:   bench_solvers_reduction [case=cases/sb1_coarse.toml] [top_speed_rpm=6000]
//                                [compression=0 (> 0: add the default basis compressed)]
//                                [only | build | twin | twin-build] [slice_fraction=0.25]
//                                [moving_moments=1 (2: the slices' second moment too)]
//                                [slice_shape=box | hat (ReductionOptions::moving_slice_shape)]
// "only": the default basis (and its compressed variant) only; "build": the same, and stop after
// the build (order, build time; run under /usr/bin/time -v for the peak memory against mesh size).
// The slice fraction (ReductionOptions::moving_slice_fraction) applies to every Krylov basis.
// "twin-build": the twin's build only (outputs, then basis), timed.
// "twin": the basis with the given compression tolerance and moving slice fraction only, as the
// twin of the case (TCP and axis-point influence rows), validated against the full model on
// solvers::validation_runs (the case's own cycle, a 6 h staircase, an 8 h irregular cycle): per
// run the largest named-point temperature error and the largest drift error over its limit
// (1 % of the full run's peak or 0.02 um), with the drift column where it is largest.
// Prints the mesh size, then per basis and duty cycle: states r, build time, the largest
// |reduced - full| over every node and output time and over the named points, the error
// indicator at the output times, and the run times. The duty cycles: the case's own (P-1 for
// SB-1), a 6 h staircase 1000, 2000, 4000, 6000, 3000, 0 rpm (1 h each), and an 8 h irregular
// cycle with 16 switches, and the staircase again under an ambient (every sink) swing of +4 / -2 K.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/timing.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/loads.hpp"
#include "solvers/reduction.hpp"
#include "solvers/thermal.hpp"
#include "solvers/thermal_stepper.hpp"
#include "solvers/twin.hpp"

namespace {

namespace s = tt::solvers;
using Clock = std::chrono::steady_clock;
using tt::core::seconds_since;

struct Cycle {
  std::string name;
  tt::core::DutyCycle duty;
};

tt::core::DutyCycle cycle_of(const std::vector<std::pair<double, double>>& segments, double end) {
  tt::core::DutyCycle d;
  for (const auto& [start, speed] : segments) d.segments.push_back({start, speed});
  d.end = end;
  return d;
}

std::vector<Cycle> test_cycles(const tt::core::CaseSpec& spec) {
  return {
      {"own", spec.duty_cycle},
      {"staircase 6 h",
       cycle_of({{0, 1000}, {3600, 2000}, {7200, 4000}, {10800, 6000}, {14400, 3000}, {18000, 0}},
                21600)},
      {"irregular 8 h", cycle_of({{0, 2500},
                                  {1500, 0},
                                  {2100, 4500},
                                  {4200, 1200},
                                  {5100, 6000},
                                  {7800, 0},
                                  {8400, 3500},
                                  {10500, 800},
                                  {11400, 5000},
                                  {13800, 2000},
                                  {15600, 0},
                                  {16200, 5500},
                                  {18900, 3000},
                                  {20700, 1500},
                                  {22800, 4000},
                                  {25200, 0},
                                  {26400, 2500}},
                                 28800)}};
}

/// The case with every sink following an ambient swing of +4 / -2 K over 6 h [degC].
tt::core::CaseSpec with_ambient_swing(tt::core::CaseSpec spec) {
  for (auto& c : spec.thermal.convection) {
    const double base = c.sink.value.front();
    c.sink.time = {0, 7200, 14400, 21600};
    c.sink.value = {base, base + 4, base - 2, base + 1};
  }
  return spec;
}

/// Record times: the output times and, for the indicator, the step end before each.
std::vector<double> record_times(const tt::core::CaseSpec& spec) {
  const std::vector<double> grid = s::time_grid(spec, spec.thermal.step);
  std::vector<double> t = s::output_times(spec);
  for (size_t i = 1; i < grid.size(); ++i)
    if (std::find(t.begin(), t.end(), grid[i]) != t.end()) t.push_back(grid[i - 1]);
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  return t;
}

Eigen::Index column_at(const s::SteppedHistory& h, double t) {
  return std::find(h.times.begin(), h.times.end(), t) - h.times.begin();
}

/// The sampled steps of a reduced run for the indicator, at the output times; the full load of
/// each step is read from the full run's own states (backward Euler: f = C (T1 - T0)/dt + K T1).
std::vector<s::ReducedStep> samples(const s::FullThermalSystem& full,
                                    const tt::core::CaseSpec& spec,
                                    const s::SteppedHistory& full_run,
                                    const s::SteppedHistory& reduced_run) {
  const std::vector<double> grid = s::time_grid(spec, spec.thermal.step);
  const std::vector<double> outs = s::output_times(spec);
  const std::vector<double> switches = s::switch_times(spec);
  std::vector<s::ReducedStep> out;
  for (size_t i = 1; i < grid.size(); ++i) {
    if (std::find(outs.begin(), outs.end(), grid[i]) == outs.end()) continue;
    s::ReducedStep st;
    const double t0 = grid[i - 1], t1 = grid[i];
    st.dt = t1 - t0;
    const double speed = s::speed_at(spec.duty_cycle, 0.5 * (t0 + t1));
    for (const auto& c : spec.thermal.convection) st.film.push_back(s::film_coefficient(c, speed));
    Eigen::SparseMatrix<double> k = full.conduction;
    for (size_t c = 0; c < st.film.size(); ++c) k += st.film[c] * full.film[c];
    const Eigen::VectorXd a = full_run.states.col(column_at(full_run, t0));
    const Eigen::VectorXd b = full_run.states.col(column_at(full_run, t1));
    st.load = full.capacity * ((b - a) / st.dt) + k * b;
    st.state_old = reduced_run.states.col(column_at(reduced_run, t0));
    st.state_new = reduced_run.states.col(column_at(reduced_run, t1));
    double last = 0;
    for (double w : switches)
      if (w < t1) last = w;
    st.horizon = t1 - last;
    out.push_back(std::move(st));
  }
  return out;
}

/// POD basis from snapshots in the capacity inner product: the uniform field and the snapshots'
/// rises, modes kept above 1e-12 of the largest.
Eigen::MatrixXd pod_basis(const s::FullThermalSystem& full, const Eigen::MatrixXd& snapshots,
                          double t0_k) {
  Eigen::MatrixXd w(snapshots.rows(), snapshots.cols() + 1);
  w.col(0).setOnes();
  w.rightCols(snapshots.cols()) = snapshots.array() - t0_k;
  const Eigen::MatrixXd g = w.transpose() * (full.capacity * w);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(g);
  const Eigen::VectorXd lambda = eig.eigenvalues();
  std::vector<Eigen::Index> keep;
  for (Eigen::Index i = lambda.size() - 1; i >= 0; --i)
    if (lambda(i) > 1e-12 * lambda.maxCoeff()) keep.push_back(i);
  Eigen::MatrixXd v(w.rows(), static_cast<Eigen::Index>(keep.size()));
  for (size_t j = 0; j < keep.size(); ++j)
    v.col(static_cast<Eigen::Index>(j)) =
        w * eig.eigenvectors().col(keep[j]) / std::sqrt(lambda(keep[j]));
  return v;
}

struct Variant {
  std::string name;
  s::ReducedModel model;
};

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress as it comes
  try {
    const std::string case_file =
        argc > 1 ? argv[1] : std::string(TT_SOURCE_DIR) + "/cases/sb1_coarse.toml";
    const double top_speed = argc > 2 ? std::atof(argv[2]) : 6000.0;
    // A compression tolerance > 0 adds the default basis compressed; "only" skips the others.
    const double compression = argc > 3 ? std::atof(argv[3]) : 0.0;
    const std::string mode = argc > 4 ? argv[4] : "";
    const bool only = mode == "only" || mode == "build";
    const s::ReductionOptions defaults;
    const double slice_fraction = argc > 5 ? std::atof(argv[5]) : defaults.moving_slice_fraction;
    const bool moving_second_moment =
        argc > 6 ? std::atoi(argv[6]) == 2 : defaults.moving_second_moment;
    const auto slice_shape =
        argc > 7 ? (std::string(argv[7]) == "hat" ? s::ReductionOptions::SliceShape::hat
                                                  : s::ReductionOptions::SliceShape::box)
                 : defaults.moving_slice_shape;
    // 1. The case, its mesh and the full system.
    tt::core::CaseSpec spec = tt::io::read_case(case_file);
    auto t = Clock::now();
    const tt::mesh::TetMesh mesh = tt::mesh::mesh_case(spec);
    const double mesh_s = seconds_since(t);
    t = Clock::now();
    const s::FullThermalSystem full = s::thermal_system(mesh, spec);
    std::printf("case %s: %d nodes, %d tets (order %d); mesh %.2f s, assembly %.2f s\n",
                case_file.c_str(), static_cast<int>(full.states()),
                static_cast<int>(mesh.tets.rows()), mesh.order, mesh_s, seconds_since(t));
    std::vector<int> points;
    for (const auto& p : spec.points) points.push_back(tt::mesh::named_node(mesh, p.id));
    const double t0_k = spec.thermal.initial_temperature_c + tt::core::kCelsiusOffset;

    if (mode == "twin" || mode == "twin-build") {
      // The twin of the case under these options, validated as `thermotwin reduce` does.
      s::ReductionOptions o;
      o.compression_tolerance = compression;
      o.moving_slice_fraction = slice_fraction;
      o.moving_slice_shape = slice_shape;
      o.moving_second_moment = moving_second_moment;
      o.speeds_rpm = {0.0, top_speed};
      t = Clock::now();
      const tt::solvers::ElasticModel elastic(mesh, spec);
      const s::TwinOutputs outputs = s::full_outputs(mesh, spec, &elastic);
      std::printf("outputs (stiffness factor %.2f s, influence rows): %.2f s\n",
                  elastic.timings().factor_s, seconds_since(t));
      s::Twin twin;
      twin.model = s::reduced_model(full, spec, o);
      twin.outputs = s::projected_outputs(outputs, twin.model.basis);
      const auto& st = twin.model.stats;
      std::printf(
          "twin compression %g, %s slices %g of a window, %d moments of the slices: r = %d, build "
          "%.2f s (%d input "
          "columns; solves %.2f s, orthogonalisation %.2f s, projection %.2f s)\n",
          compression, slice_shape == s::ReductionOptions::SliceShape::hat ? "hat" : "box",
          slice_fraction, moving_second_moment ? 2 : 1, twin.model.states(), st.build_s,
          st.input_columns, st.solve_s, st.orthogonalise_s, st.projection_s);
      if (mode == "twin-build") return 0;
      const auto table = s::validate_twin(full, outputs, twin, s::validation_runs(spec, spec.seed));
      for (const auto& c : table) {
        Eigen::Index worst = 0;
        const Eigen::VectorXd ratio = c.drift_error_m.cwiseQuotient(c.drift_limit_m);
        const double r = ratio.size() ? ratio.maxCoeff(&worst) : 0.0;
        std::printf(
            "  %-28s max|dT| named %.2e K (%s); drift error / limit %.3f at %s (%.2e of "
            "%.2e um)\n",
            c.run.c_str(), c.max_temperature_error_k, c.worst_point.c_str(), r,
            ratio.size() ? c.drift_names[static_cast<size_t>(worst)].c_str() : "-",
            ratio.size() ? c.drift_error_m(worst) * 1e6 : 0.0,
            ratio.size() ? c.drift_limit_m(worst) * 1e6 : 0.0);
      }
      return 0;
    }

    // 2. The bases.
    std::vector<Variant> variants;
    const auto krylov = [&](const std::string& name, std::vector<double> shifts, bool second,
                            double compress = 0) {
      s::ReductionOptions o;
      o.compression_tolerance = compress;
      o.moving_slice_fraction = slice_fraction;
      o.moving_slice_shape = slice_shape;
      o.moving_second_moment = moving_second_moment;
      o.speeds_rpm = {0.0, top_speed};
      o.shifts_per_s = std::move(shifts);
      o.second_moment = second;
      variants.push_back({name, s::reduced_model(full, spec, o)});
    };
    const auto logspace = [](int count) {
      std::vector<double> v = {0.0};
      for (int i = 0; i < count; ++i)
        v.push_back(count == 1 ? 1.0 / 3600
                               : (1.0 / 36000) * std::pow(36000.0 / 12.0, i / double(count - 1)));
      return v;
    };
    krylov("krylov 0+5 shifts, 2 moments (default)", {}, true);
    if (compression > 0)
      krylov("  compressed " + std::to_string(compression), {}, true, compression);
    if (!only) {
      krylov("krylov 0+5 shifts, 1 moment", logspace(5), false);
      krylov("krylov 0+2 shifts, 1 moment", logspace(2), false);
      krylov("krylov 0+8 shifts, 1 moment", logspace(8), false);
    }
    if (!only) {
      // POD from the full run of the case's own cycle: its states at every output time.
      t = Clock::now();
      s::StepperRequest q;
      q.record_times = s::output_times(spec);
      const s::SteppedHistory train = s::step_thermal(full, spec, q);
      s::ReducedModel m;
      m.basis = pod_basis(full, train.states, t0_k);
      m.system = s::projected_system(full, m.basis);
      m.stats.build_s = seconds_since(t);
      variants.push_back({"POD from the case's own cycle", std::move(m)});
    }
    for (const auto& v : variants)
      std::printf(
          "basis %-40s r = %3d, build %.2f s (%d factors, %d of %d columns deflated; %d input "
          "columns; solves %.2f s, orthogonalisation %.2f s, projection %.2f s)\n",
          v.name.c_str(), v.model.states(), v.model.stats.build_s, v.model.stats.factorizations,
          v.model.stats.deflated_columns, v.model.stats.candidate_columns,
          v.model.stats.input_columns, v.model.stats.solve_s, v.model.stats.orthogonalise_s,
          v.model.stats.projection_s);
    if (mode == "build") return 0;

    // 3. Per duty cycle: the full run, then every reduced one against it.
    std::vector<Cycle> cycles = test_cycles(spec);
    cycles.push_back({"staircase 6 h, ambient swing", cycles[1].duty});
    for (const auto& cycle : cycles) {
      tt::core::CaseSpec run =
          cycle.name.find("swing") != std::string::npos ? with_ambient_swing(spec) : spec;
      run.duty_cycle = cycle.duty;
      s::StepperRequest q;
      q.record_times = record_times(run);
      t = Clock::now();
      const s::SteppedHistory ref = s::step_thermal(full, run, q);
      const double full_s = seconds_since(t);
      double rise = (ref.states.array() - t0_k).abs().maxCoeff();
      std::printf("\ncycle %s: %d steps, full run %.2f s, largest rise %.2f K\n",
                  cycle.name.c_str(), ref.timings.steps, full_s, rise);
      const std::vector<double> outs = s::output_times(run);
      for (const auto& v : variants) {
        t = Clock::now();
        const s::SteppedHistory red = s::step_thermal(v.model.system, run, q);
        const double red_s = seconds_since(t);
        double all = 0, named = 0;
        for (double to : outs) {
          const Eigen::VectorXd diff = v.model.basis * red.states.col(column_at(red, to)) -
                                       ref.states.col(column_at(ref, to));
          all = std::max(all, diff.cwiseAbs().maxCoeff());
          for (int p : points) named = std::max(named, std::abs(diff(p)));
        }
        t = Clock::now();
        const auto ind = s::error_indicator(full, v.model, samples(full, run, ref, red));
        const double ind_s = seconds_since(t);
        std::printf(
            "  %-40s max|dT| nodes %.2e K, named points %.2e K; indicator %.2e K (%zu "
            "samples, %.2f s); reduced run %.3f s\n",
            v.name.c_str(), all, named, ind.max_k, ind.samples_k.size(), ind_s, red_s);
      }
    }
    return 0;
  } catch (const tt::core::Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
