// The one place OpenMP is used. Approved parallel loops: element assembly (thread-local results
// concatenated in a fixed order), candidate scoring and GA fitness evaluation. Results never
// depend on the thread count: every loop body writes only its own slot.
#pragma once

#include <cstddef>
#include <vector>

namespace tt::core {

/// Runs body(i) for i in [0, n), possibly in parallel. body must write only to slot i.
template <class Body>
void parallel_for(std::ptrdiff_t n, Body&& body) {
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < n; ++i) body(i);
}

/// Splits [0, n) into fixed contiguous chunks (independent of the thread count), runs
/// chunk_body(begin, end, chunk) on each, possibly in parallel, and returns the chunk results
/// in chunk order so that concatenation is deterministic.
template <class Result, class ChunkBody>
std::vector<Result> parallel_chunks(std::ptrdiff_t n, std::ptrdiff_t chunk_size, ChunkBody&& chunk_body) {
  const std::ptrdiff_t chunks = n == 0 ? 0 : (n + chunk_size - 1) / chunk_size;
  std::vector<Result> results(static_cast<std::size_t>(chunks));
#pragma omp parallel for schedule(dynamic)
  for (std::ptrdiff_t c = 0; c < chunks; ++c) {
    const std::ptrdiff_t begin = c * chunk_size;
    const std::ptrdiff_t end = begin + chunk_size < n ? begin + chunk_size : n;
    results[static_cast<std::size_t>(c)] = chunk_body(begin, end, c);
  }
  return results;
}

}  // namespace tt::core
