// Synthetic thermal runs for the fitting tests: a duty cycle heats sensors that respond with
// their own time constants, on top of a slow ambient drift; targets are set by each test.
#pragma once

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "core/rng.hpp"
#include "core/units.hpp"
#include "fitting/features.hpp"
#include "fitting/group.hpp"

namespace tt::fitting::test {

/// Sensor k: 20 °C + gain_k · lowpass_{tau_k}(duty) + ambient_k · drift; no error columns yet.
inline Group thermal_run(int index, std::uint64_t seed, int sensors = 6,
                         double duration = 5 * 3600.0, double step = 60.0) {
  std::mt19937_64 rng = core::generator(seed, static_cast<std::uint64_t>(index));
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const auto n = static_cast<Eigen::Index>(std::floor(duration / step)) + 1;
  Group g;
  g.name = "run" + std::to_string(index);
  g.time = Eigen::VectorXd::LinSpaced(n, 0.0, step * static_cast<double>(n - 1));
  // Spindle duty: a new random level every 20 to 60 minutes.
  Eigen::VectorXd duty(n);
  double level = uniform(rng);
  double next_change = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (g.time(i) >= next_change) {
      level = uniform(rng) < 0.25 ? 0.0 : uniform(rng);
      next_change = g.time(i) + 1200.0 + 2400.0 * uniform(rng);
    }
    duty(i) = level;
  }
  const double phase = 2.0 * std::numbers::pi * uniform(rng);
  const double drift_amplitude = 0.5 + uniform(rng);
  Eigen::VectorXd drift(n);
  for (Eigen::Index i = 0; i < n; ++i)
    drift(i) =
        drift_amplitude * std::sin(2.0 * std::numbers::pi * g.time(i) / 86400.0 * 3.0 + phase);
  const double taus[] = {300.0, 900.0, 1800.0, 3600.0, 5400.0, 7200.0, 1200.0, 2400.0};
  const double gains[] = {12.0, 9.0, 7.0, 5.0, 4.0, 3.0, 8.0, 6.0};
  const double ambient[] = {0.2, 0.5, 0.8, 0.3, 1.0, 0.6, 0.1, 0.9};
  g.temperature.resize(n, sensors);
  for (int k = 0; k < sensors; ++k) {
    g.temperature.col(k) = (20.0 + core::kCelsiusOffset) +
                           gains[k % 8] * low_pass(g.time, duty, taus[k % 8]).array() +
                           ambient[k % 8] * drift.array();
    g.sensor_names.push_back("t" + std::to_string(k + 1));
  }
  g.error.resize(n, 0);
  return g;
}

/// Adds an error column computed by f(group) [m] plus Gaussian noise sigma [m].
template <class F>
void add_target(Group& g, const std::string& name, F&& f, double sigma, std::uint64_t seed,
                std::uint64_t stream) {
  std::mt19937_64 rng = core::generator(seed, stream);
  std::normal_distribution<double> normal(0.0, sigma);
  Eigen::VectorXd e = f(g);
  for (Eigen::Index i = 0; i < e.size(); ++i) e(i) += sigma > 0.0 ? normal(rng) : 0.0;
  g.error.conservativeResize(g.time.size(), g.error.cols() + 1);
  g.error.rightCols(1) = e;
  g.target_names.push_back(name);
}

/// A campaign of `count` runs with one target f plus noise sigma.
template <class F>
std::vector<Group> campaign(int count, std::uint64_t seed, F&& f, double sigma, int sensors = 6,
                            double step = 60.0) {
  std::vector<Group> groups;
  for (int i = 0; i < count; ++i) {
    Group g = thermal_run(i, seed, sensors, 5 * 3600.0, step);
    add_target(g, "z", f, sigma, seed + 1000, static_cast<std::uint64_t>(i));
    groups.push_back(g);
  }
  return groups;
}

/// ΔT of sensor k in a group [K].
inline Eigen::VectorXd increment(const Group& g, int k) {
  return g.temperature.col(k).array() - g.temperature(0, k);
}

}  // namespace tt::fitting::test
