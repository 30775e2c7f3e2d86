// Seeds derived from one master seed, so results do not depend on the thread count or on the
// order in which work is scheduled.
#pragma once

#include <cstdint>
#include <random>

namespace tt::core {

/// splitmix64 of (master, stream): a well-mixed seed for an independent generator per item.
constexpr std::uint64_t derived_seed(std::uint64_t master, std::uint64_t stream) {
  std::uint64_t z = master + 0x9E3779B97F4A7C15ull * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// A generator for item `stream` of a computation seeded by `master`.
inline std::mt19937_64 generator(std::uint64_t master, std::uint64_t stream) {
  return std::mt19937_64(derived_seed(master, stream));
}

}  // namespace tt::core
