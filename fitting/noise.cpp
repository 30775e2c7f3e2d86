#include "fitting/noise.hpp"

#include <cmath>
#include <random>
#include <string>

#include "core/errors.hpp"
#include "core/rng.hpp"

namespace tt::fitting {

Group noisy_group(const Group& group, const SensorNoise& noise, std::uint64_t master_seed,
                  std::uint64_t stream) {
  if (!(noise.temperature_sigma >= 0.0) || !(noise.temperature_resolution >= 0.0) ||
      !(noise.error_sigma >= 0.0))
    throw core::DataError(
        "sensor noise: temperature_sigma = " + std::to_string(noise.temperature_sigma) +
        " K, temperature_resolution = " + std::to_string(noise.temperature_resolution) +
        " K, error_sigma = " + std::to_string(noise.error_sigma) + " m; each must be >= 0");
  std::mt19937_64 rng = core::generator(master_seed, stream);
  std::normal_distribution<double> normal(0.0, 1.0);
  Group noisy = group;
  // Column-major order, temperatures first, fixes which draw goes where.
  for (Eigen::Index j = 0; j < noisy.temperature.cols(); ++j)
    for (Eigen::Index i = 0; i < noisy.temperature.rows(); ++i) {
      double t = noisy.temperature(i, j) + noise.temperature_sigma * normal(rng);
      if (noise.temperature_resolution > 0.0)
        t = noise.temperature_resolution * std::round(t / noise.temperature_resolution);
      noisy.temperature(i, j) = t;
    }
  for (Eigen::Index j = 0; j < noisy.error.cols(); ++j)
    for (Eigen::Index i = 0; i < noisy.error.rows(); ++i)
      noisy.error(i, j) += noise.error_sigma * normal(rng);
  return noisy;
}

}  // namespace tt::fitting
