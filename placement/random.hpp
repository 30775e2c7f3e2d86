// Portable draws from a 64-bit generator: the standard distributions are implementation-defined,
// these give the same numbers with every standard library, so a seed means the same run everywhere.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

namespace tt::placement {

/// Uniform index in [0, n) without modulo bias (n > 0).
inline std::int64_t uniform_index(std::mt19937_64& gen, std::int64_t n) {
  const auto range = static_cast<std::uint64_t>(n);
  const std::uint64_t limit = UINT64_MAX - UINT64_MAX % range;
  std::uint64_t draw = gen();
  while (draw >= limit) draw = gen();
  return static_cast<std::int64_t>(draw % range);
}

/// Uniform real in [0, 1) with 53 random bits.
inline double uniform_unit(std::mt19937_64& gen) {
  return static_cast<double>(gen() >> 11) * 0x1.0p-53;
}

/// A uniformly random permutation of 0..n-1 (Fisher-Yates).
inline std::vector<int> random_permutation(std::mt19937_64& gen, int n) {
  std::vector<int> p(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) p[static_cast<std::size_t>(i)] = i;
  for (int i = n - 1; i > 0; --i) {
    const auto j = static_cast<std::size_t>(uniform_index(gen, i + 1));
    std::swap(p[static_cast<std::size_t>(i)], p[j]);
  }
  return p;
}

}  // namespace tt::placement
