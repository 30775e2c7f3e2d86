// The memory-bandwidth bound of a thermal time step: one back-substitution reads the Cholesky
// factor twice (forward, then backward), so on a factor larger than the last-level cache a step
// cannot take less than 2 x (factor bytes) / (streaming read bandwidth).
//
// Run:   bench_solvers_bandwidth [case=cases/sb1.toml] [order=2] [solves=30]
// Prints the machine's streaming bandwidth (read, copy, triad; best of several repeats, one
// thread), the factor of SB-1's thermal matrix M + dt K (dt = the case's thermal step), the
// median of `solves` single back-substitutions and its ratio to the bound (target: within 2x).
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/timing.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/cholmod/cholmod_factor.hpp"
#include "solvers/loads.hpp"
#include "solvers/thermal.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using tt::core::seconds_since;

/// CPU time of the calling thread [s]: unlike wall time, it excludes the time the thread waits
/// while other processes hold the cores (the bench machine is shared).
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Streaming bandwidths of one thread [B/s], each the best of `repeats` passes over arrays far
/// larger than any cache.
struct Bandwidth {
  double read = 0, copy = 0, triad = 0;
  double read_per_cpu_s = 0;  /// read bytes per second of this thread's CPU time
};

Bandwidth streaming_bandwidth(std::size_t n, int repeats) {
  std::vector<double> a(n, 1.0), b(n, 2.0), c(n, 0.5);
  Bandwidth bw;
  volatile double sink = 0;
  for (int r = 0; r < repeats; ++r) {
    auto t0 = Clock::now();
    const double c0 = thread_cpu_seconds();
    // Eight independent sums so that the adds keep up with memory.
    double s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t i = 0; i + 8 <= n; i += 8)
      for (int k = 0; k < 8; ++k) s[k] += b[i + k];
    sink = sink + std::accumulate(s, s + 8, 0.0);
    bw.read = std::max(bw.read, 8.0 * n / seconds_since(t0));
    bw.read_per_cpu_s = std::max(bw.read_per_cpu_s, 8.0 * n / (thread_cpu_seconds() - c0));

    t0 = Clock::now();
    std::copy(b.begin(), b.end(), a.begin());
    bw.copy = std::max(bw.copy, 16.0 * n / seconds_since(t0));

    t0 = Clock::now();
    const double scale = 1.0 + 1e-3 * r;
    for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + scale * c[i];
    bw.triad = std::max(bw.triad, 24.0 * n / seconds_since(t0));
    sink = sink + a[n / 2];
  }
  return bw;
}

/// Size of the last-level cache [B] from sysfs (the highest cache index of cpu0), 0 if unknown.
double last_level_cache_bytes() {
  double best = 0;
  for (int idx = 0; idx < 8; ++idx) {
    std::ifstream in("/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(idx) + "/size");
    std::string text;
    if (!(in >> text)) break;
    double v = std::atof(text.c_str());
    if (text.back() == 'K') v *= 1024;
    if (text.back() == 'M') v *= 1024 * 1024;
    best = std::max(best, v);
  }
  return best;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

}  // namespace

int main(int argc, char** argv) {
  namespace ts = tt::solvers;
  try {
    const std::string case_file = argc > 1 ? argv[1] : TT_SOURCE_DIR "/cases/sb1.toml";
    const int order = argc > 2 ? std::atoi(argv[2]) : 2;
    const int solves = argc > 3 ? std::max(20, std::atoi(argv[3])) : 30;
    ts::cholmod::set_blas_threads(1);

    // 1. The machine: streaming bandwidth on 3 x 256 MiB arrays, and the last-level cache.
    const Bandwidth bw = streaming_bandwidth(std::size_t{32} << 20, 8);
    const double llc = last_level_cache_bytes();
    std::printf(
        "bandwidth (1 thread, best of 8): read %.2f GB/s, copy %.2f GB/s, triad %.2f GB/s\n",
        bw.read * 1e-9, bw.copy * 1e-9, bw.triad * 1e-9);
    std::printf("read bandwidth per CPU second of the thread: %.2f GB/s\n",
                bw.read_per_cpu_s * 1e-9);
    std::printf("last-level cache: %.1f MiB\n", llc / (1 << 20));

    // 2. SB-1 meshed at the requested order, and its thermal operators.
    tt::core::CaseSpec spec = tt::io::read_case(case_file);
    spec.mesh.order = order;
    auto t0 = Clock::now();
    const tt::mesh::TetMesh mesh = tt::mesh::mesh_case(spec);
    const double mesh_s = seconds_since(t0);
    t0 = Clock::now();
    const ts::FullThermalSystem ops = ts::thermal_system(mesh, spec);
    const double assemble_s = seconds_since(t0);

    // 3. The step matrix M + dt (K + sum h F) at full speed, factored once.
    const double dt = spec.thermal.step;
    Eigen::SparseMatrix<double> k = ops.conduction;
    for (std::size_t c = 0; c < spec.thermal.convection.size(); ++c)
      k += ts::film_coefficient(spec.thermal.convection[c], 3000.0) * ops.film[c];
    Eigen::SparseMatrix<double> a = ops.capacity + dt * k;
    a.makeCompressed();
    t0 = Clock::now();
    const ts::cholmod::Factor factor(a, "SB-1 thermal step matrix");
    const double factor_s = seconds_since(t0);
    const double entries = factor.factor_entries();
    const double factor_bytes = 8.0 * entries;  // values only; supernodal row indices are few
    std::printf("mesh: order %d, %ld nodes, %ld tets (%.1f s); assembly %.1f s; factor %.2f s\n",
                order, static_cast<long>(mesh.nodes.rows()), static_cast<long>(mesh.tets.rows()),
                mesh_s, assemble_s, factor_s);
    std::printf("factor: %.3g entries = %.1f MiB (%.1f x the last-level cache)\n", entries,
                factor_bytes / (1 << 20), llc > 0 ? factor_bytes / llc : 0.0);

    // 4. Single back-substitutions, each on a fresh copy of one right-hand side.
    const Eigen::VectorXd rhs = ops.capacity * Eigen::VectorXd::Constant(a.rows(), 293.15) +
                                dt * ops.source_shape.front() * 80.0;
    std::vector<double> times, cpu_times;
    Eigen::VectorXd x(rhs.size());
    for (int s = 0; s < solves + 2; ++s) {
      x = rhs;
      t0 = Clock::now();
      const double c0 = thread_cpu_seconds();
      factor.solve_in_place(x);
      if (s < 2) continue;  // the first two warm the workspace
      cpu_times.push_back(thread_cpu_seconds() - c0);
      times.push_back(seconds_since(t0));
    }
    const double residual = (a * x - rhs).norm() / rhs.norm();
    const double bound_s = 2.0 * factor_bytes / bw.read;
    const double med = median(times);
    std::printf(
        "solve: %d back-substitutions, median %.2f ms, best %.2f ms (relative residual %.1e)\n",
        solves, med * 1e3, *std::min_element(times.begin(), times.end()) * 1e3, residual);
    std::printf("bound: 2 x %.1f MiB / %.2f GB/s = %.2f ms; median / bound = %.2f (target <= 2)\n",
                factor_bytes / (1 << 20), bw.read * 1e-9, bound_s * 1e3, med / bound_s);
    // The same in CPU time of the thread, which a shared, oversubscribed machine does not inflate.
    const double bound_cpu_s = 2.0 * factor_bytes / bw.read_per_cpu_s;
    std::printf("in thread CPU time: median solve %.2f ms, bound %.2f ms, ratio %.2f\n",
                median(cpu_times) * 1e3, bound_cpu_s * 1e3, median(cpu_times) / bound_cpu_s);
    std::printf("effective bandwidth of the solve: %.2f GB/s\n", 2.0 * factor_bytes / med * 1e-9);
    return 0;
  } catch (const tt::core::Error& e) {
    std::fprintf(stderr, "bench_solvers_bandwidth: error: %s\n", e.what());
    return 1;
  }
}
