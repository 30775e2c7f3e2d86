// Shared virtual spindles for the probe tests: 5 µm runout with form error, 0.1 µm noise.
#pragma once

#include <cmath>
#include <filesystem>
#include <string>

#include "probes/virtual_signal.hpp"

namespace tt::probes::fixtures {

/// 3000 rpm at 10 kHz (200 samples per revolution), 2.5 revolutions per reading, D = 150 mm,
/// 5 µm eccentricity (plus harmonics) at both planes with different phases, 0.1 µm noise.
inline VirtualProbeSetup runout_setup(std::uint64_t seed) {
  VirtualProbeSetup s;
  s.seed = seed;
  s.runout_plane1 = spindle_runout(5e-6, 0.3);
  s.runout_plane2 = spindle_runout(5e-6, 1.4);
  s.runout_axial = spindle_runout(1e-6, 2.0);
  s.noise_std_m = 0.1e-6;
  return s;
}

/// Warm-up drift over two hours, one reading every 10 min: first-order growth with different
/// amplitudes per direction, so that both planes tilt.
inline DriftHistory warm_up_history(int readings = 13) {
  DriftHistory h;
  for (int i = 0; i < readings; ++i) {
    const double t = 600.0 * i;
    const double g = 1.0 - std::exp(-t / 2400.0);
    h.push_back({t, {8e-6 * g, -12e-6 * g, 11e-6 * g, -9e-6 * g, 20e-6 * g}});
  }
  return h;
}

/// A fresh, empty directory for one test's files under the build tree.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(TT_BINARY_DIR) / "probes_test_tmp" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace tt::probes::fixtures
