#pragma once

// A minimal fork-join loop over an index range for the dense stage, which
// starts its threads per call (it nests loops: photos in flight, rows within;
// format/parallel.h's pool would run the inner ones on one thread). Work is
// split into contiguous chunks handed out dynamically, so uneven rows or
// planes still keep every thread busy. Deterministic results only require that
// the body writes disjoint outputs per index.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "format/parallel.h"

namespace casual3d::depth {

// Number of worker threads for `requested` (0 = all hardware threads).
using casual3d::ResolveThreads;

// Calls body(i) for every i in [begin, end) on up to `num_threads` threads.
// `grain` indices are claimed at a time. Exceptions must not escape `body`.
template <typename Body>
void ParallelFor(int64_t begin, int64_t end, int num_threads, Body&& body, int64_t grain = 1) {
  if (end <= begin) return;
  const int threads = static_cast<int>(
      std::min<int64_t>(std::max(1, num_threads), (end - begin + grain - 1) / grain));
  if (threads <= 1) {
    for (int64_t i = begin; i < end; ++i) body(i);
    return;
  }
  std::atomic<int64_t> next(begin);
  auto worker = [&]() {
    for (;;) {
      const int64_t start = next.fetch_add(grain);
      if (start >= end) break;
      const int64_t stop = std::min(end, start + grain);
      for (int64_t i = start; i < stop; ++i) body(i);
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
}

}  // namespace casual3d::depth
