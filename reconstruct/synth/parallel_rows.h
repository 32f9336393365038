#pragma once

// Runs fn(y) for every row y in [0, rows) on `num_threads` std::threads with a
// fixed partition (thread k takes rows k, k + T, k + 2T, ...). Each row must be
// a pure function of its index, so results do not depend on the thread count.

#include <algorithm>
#include <thread>
#include <vector>

namespace casual3d::synth {

// 0 means all hardware threads.
inline int ResolveThreads(int num_threads) {
  if (num_threads > 0) return num_threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

template <typename Fn>
void ParallelRows(int rows, int num_threads, Fn&& fn) {
  const int threads = std::min(ResolveThreads(num_threads), std::max(rows, 1));
  if (threads <= 1) {
    for (int y = 0; y < rows; ++y) fn(y);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(threads);
  for (int k = 0; k < threads; ++k) {
    pool.emplace_back([&, k] {
      for (int y = k; y < rows; y += threads) fn(y);
    });
  }
  for (std::thread& t : pool) t.join();
}

}  // namespace casual3d::synth
