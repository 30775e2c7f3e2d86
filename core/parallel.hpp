// The one place OpenMP is used. Approved parallel loops: element assembly (thread-local results
// concatenated in a fixed order), candidate scoring, GA fitness evaluation, and independent sparse
// factorisations (the reduced basis's shifts; a twin's thermal basis beside its elastic outputs).
// Results never depend on the thread count: every loop body writes only its own slot. A body that
// throws does not end the program: the exception of the lowest index is rethrown once the loop is
// done (OpenMP itself would call std::terminate).
#pragma once

#include <cstddef>
#include <exception>
#include <vector>

namespace tt::core {

namespace detail {

/// body(i) for i in [0, n), each exception kept in its slot; rethrows the lowest index's.
template <class Body>
void guarded_loop(std::ptrdiff_t n, Body&& body, bool dynamic) {
  std::vector<std::exception_ptr> failed(static_cast<std::size_t>(n > 0 ? n : 0));
  const auto one = [&](std::ptrdiff_t i) {
    try {
      body(i);
    } catch (...) {
      failed[static_cast<std::size_t>(i)] = std::current_exception();
    }
  };
  if (dynamic) {
#pragma omp parallel for schedule(dynamic)
    for (std::ptrdiff_t i = 0; i < n; ++i) one(i);
  } else {
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < n; ++i) one(i);
  }
  for (const auto& e : failed)
    if (e) std::rethrow_exception(e);
}

}  // namespace detail

/// Runs body(i) for i in [0, n), possibly in parallel. body must write only to slot i.
template <class Body>
void parallel_for(std::ptrdiff_t n, Body&& body) {
  detail::guarded_loop(n, body, false);
}

/// Runs first() and second() side by side (two independent pieces of work, e.g. two factors).
/// Inside, a nested parallel loop runs on its caller's thread only.
template <class First, class Second>
void parallel_invoke(First&& first, Second&& second) {
  parallel_for(2, [&](std::ptrdiff_t i) { i == 0 ? first() : second(); });
}

/// Splits [0, n) into fixed contiguous chunks (independent of the thread count), runs
/// chunk_body(begin, end, chunk) on each, possibly in parallel, and returns the chunk results
/// in chunk order so that concatenation is deterministic.
template <class Result, class ChunkBody>
std::vector<Result> parallel_chunks(std::ptrdiff_t n, std::ptrdiff_t chunk_size,
                                    ChunkBody&& chunk_body) {
  const std::ptrdiff_t chunks = n == 0 ? 0 : (n + chunk_size - 1) / chunk_size;
  std::vector<Result> results(static_cast<std::size_t>(chunks));
  detail::guarded_loop(
      chunks,
      [&](std::ptrdiff_t c) {
        const std::ptrdiff_t begin = c * chunk_size;
        const std::ptrdiff_t end = begin + chunk_size < n ? begin + chunk_size : n;
        results[static_cast<std::size_t>(c)] = chunk_body(begin, end, c);
      },
      true);
  return results;
}

}  // namespace tt::core
