#pragma once

// The native fork-join loop of encoder/ and reconstruct/: one ParallelFor
// that starts its threads per call and passes exceptions back to the caller.
//
// Threads are started per call (about 20 us each), not taken from a pool, so
// that loops nest: the dense stage runs photos in flight and rows within each,
// and an inner loop must get threads of its own. format/parallel.h keeps a
// pooled loop for the format library, which also builds to WebAssembly, where
// starting a thread (a Web Worker) per loop would cost far more.
//
// Indices are claimed `grain` at a time in increasing order by whichever
// thread is free, so uneven work keeps every thread busy. Results are the
// same for any thread count when the body writes disjoint outputs per index
// (callers that gather per-index or per-thread results combine them in a
// fixed order).

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace casual3d::base {

// Threads for `requested`: requested itself when positive, else every
// hardware thread (at least 1).
inline int ResolveThreads(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

// Calls body(i) for every i in [begin, end) on up to max(1, num_threads)
// threads, the calling thread being one of them. A body that also takes an
// int, body(i, thread), gets the number of the thread running it, in
// [0, max(1, num_threads)), for scratch memory kept per thread (the calling
// thread is 0).
//
// An exception thrown by the body ends the loop: no index is started after
// it, the other threads finish the index they are in, and the first
// exception thrown is rethrown on the calling thread once all have stopped.
// With one thread the loop runs in order on the caller and the exception
// leaves it directly.
template <typename Body>
void ParallelFor(int64_t begin, int64_t end, int num_threads, Body&& body, int64_t grain = 1) {
  if (end <= begin) return;
  grain = std::max<int64_t>(1, grain);
  const auto call = [&body](int64_t i, int thread) {
    if constexpr (std::is_invocable_v<Body&, int64_t, int>) {
      body(i, thread);
    } else {
      (void)thread;
      body(i);
    }
  };
  const int64_t claims = (end - begin - 1) / grain + 1;
  const int threads = static_cast<int>(std::min<int64_t>(std::max(1, num_threads), claims));
  if (threads == 1) {
    for (int64_t i = begin; i < end; ++i) call(i, 0);
    return;
  }
  std::atomic<int64_t> next(begin);
  std::atomic<bool> failed(false);
  std::mutex error_mutex;
  std::exception_ptr error;
  const auto fail = [&](std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(error_mutex);
    if (!error) error = std::move(e);
    failed.store(true);
  };
  const auto run = [&](int thread) {
    try {
      while (!failed.load(std::memory_order_relaxed)) {
        const int64_t start = next.fetch_add(grain);
        if (start >= end) return;
        const int64_t stop = std::min(end, start + grain);
        for (int64_t i = start; i < stop; ++i) call(i, thread);
      }
    } catch (...) {
      fail(std::current_exception());
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  try {
    for (int t = 1; t < threads; ++t) pool.emplace_back(run, t);
  } catch (...) {  // The system refused a thread: stop the ones started.
    fail(std::current_exception());
  }
  run(0);
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace casual3d::base
