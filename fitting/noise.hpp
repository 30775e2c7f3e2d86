// Sensor noise for a virtual measurement campaign: what a real thermocouple chain and a
// displacement probe would add to the simulated histories.
#pragma once

#include <cstdint>

#include "fitting/group.hpp"

namespace tt::fitting {

struct SensorNoise {
  /// standard deviation of the temperature noise [K]
  double temperature_sigma = 0.05;
  /// temperature resolution: readings are rounded to multiples of it [K]; 0 = no rounding
  double temperature_resolution = 0.01;
  /// standard deviation of the displacement (error) noise [m]
  double error_sigma = 0.3e-6;
};

/// The group with independent Gaussian noise added to every temperature (then quantised) and
/// every error reading. Reproducible: the generator is derived from (master_seed, stream), so give
/// each group of a campaign its own stream.
Group noisy_group(const Group& group, const SensorNoise& noise, std::uint64_t master_seed,
                  std::uint64_t stream);

}  // namespace tt::fitting
