#pragma once

// A minimal fork-join loop over an index range, for the format library's
// per-pixel passes (decoding, validation, mesh building).
// Work is split into chunks of `grain` indices handed out dynamically, so
// uneven rows keep every thread busy. Results are deterministic when the body
// writes disjoint outputs per index (callers that gather per-chunk results
// combine them in index order).
//
// Standard library only. A WebAssembly build without threads (Emscripten
// without -pthread) runs every loop on the calling thread. A threaded one
// (Emscripten -pthread) starts threads from a pool of Web Workers created when
// the module loads, which must not run dry: the pool holds min(hardware
// threads, CASUAL3D_MAX_THREADS) - 1 workers (wasm-viewer/CMakeLists.txt), and
// ResolveThreads never asks for more.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <vector>

#if !defined(__EMSCRIPTEN__) || defined(__EMSCRIPTEN_PTHREADS__)
#define CASUAL3D_HAS_THREADS 1
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#else
#define CASUAL3D_HAS_THREADS 0
#endif

namespace casual3d {

// Number of threads for `requested` (0 = all hardware threads), at least 1
// and at most CASUAL3D_MAX_THREADS where the build defines it; always 1
// without threads.
inline int ResolveThreads(int requested) {
#if CASUAL3D_HAS_THREADS
  const unsigned reported = std::thread::hardware_concurrency();
  const int hw = reported == 0 ? 1 : static_cast<int>(reported);
  int n = requested > 0 ? requested : hw;
#ifdef __EMSCRIPTEN_PTHREADS__
  // The pool holds one worker fewer than the hardware threads (at most
  // CASUAL3D_MAX_THREADS - 1); asking for more would wait for ever.
  n = std::min(n, hw);
#endif
#ifdef CASUAL3D_MAX_THREADS
  n = std::min(n, CASUAL3D_MAX_THREADS);
#endif
  return std::max(1, n);
#else
  (void)requested;
  return 1;
#endif
}

#if CASUAL3D_HAS_THREADS
namespace internal {

// Threads that live as long as the process and run one job at a time: a
// WebAssembly thread is a Web Worker, which takes far longer to start for
// each loop (about 0.15 ms) than to wake. After a job, pool threads and the
// caller spin briefly before they sleep, since loops often come in quick
// succession (one per decoded image). A loop started while the pool is busy
// (from a pool thread, or from a second caller) runs on its caller's thread
// alone.
class ThreadPool {
 public:
  static ThreadPool& Get() {
    static ThreadPool* pool = new ThreadPool();  // Never destroyed: its threads never end.
    return *pool;
  }

  // Runs `work` on the calling thread and on `helpers` pool threads, and
  // returns when all are done; false (running nothing) if the pool is busy.
  bool Run(int helpers, const std::function<void()>& work) {
    bool idle = false;
    if (InPoolThread() || !busy_.compare_exchange_strong(idle, true)) return false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      while (static_cast<int>(threads_.size()) < helpers) {
        const int index = static_cast<int>(threads_.size());
        threads_.emplace_back([this, index] { Loop(index); });
        threads_.back().detach();
      }
      job_ = &work;
      wanted_ = helpers;
      running_.store(helpers);
      generation_.fetch_add(1);
    }
    wake_.notify_all();
    work();
    for (int spin = 0; running_.load() != 0; ++spin) {
      if (spin < kSpins) continue;
      std::unique_lock<std::mutex> lock(mutex_);
      done_.wait(lock, [this] { return running_.load() == 0; });
      break;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = nullptr;
    }
    busy_.store(false);
    return true;
  }

 private:
  // About 0.1 ms of spinning.
  static constexpr int kSpins = 20000;

  ThreadPool() = default;

  static bool& InPoolThread() {
    static thread_local bool in_pool = false;
    return in_pool;
  }

  void Loop(int index) {
    InPoolThread() = true;
    uint64_t seen = 0;
    for (;;) {
      int spin = 0;
      while (generation_.load() == seen && spin < kSpins) ++spin;
      if (generation_.load() == seen) {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return generation_.load() != seen; });
      }
      const std::function<void()>* job;
      int wanted;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        seen = generation_.load();
        job = job_;
        wanted = wanted_;
      }
      if (index >= wanted || job == nullptr) continue;
      (*job)();
      if (running_.fetch_sub(1) == 1) {
        std::lock_guard<std::mutex> lock(mutex_);
        done_.notify_one();
      }
    }
  }

  std::atomic<bool> busy_{false};
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::vector<std::thread> threads_;
  const std::function<void()>* job_ = nullptr;  // Guarded by mutex_.
  int wanted_ = 0;                              // Guarded by mutex_.
  std::atomic<uint64_t> generation_{0};
  std::atomic<int> running_{0};
};

}  // namespace internal
#endif

// Calls body(i) for every i in [begin, end) on up to `num_threads` threads
// (the calling thread is one of them; the others come from a pool that lives
// as long as the process), claiming `grain` indices at a time. Exceptions
// must not escape `body`.
template <typename Body>
void ParallelFor(int64_t begin, int64_t end, int num_threads, Body&& body, int64_t grain = 1) {
  if (end <= begin) return;
  grain = std::max<int64_t>(1, grain);
  const int threads = static_cast<int>(
      std::min<int64_t>(std::max(1, num_threads), (end - begin + grain - 1) / grain));
#if CASUAL3D_HAS_THREADS
  if (threads > 1) {
    std::atomic<int64_t> next(begin);
    const std::function<void()> worker = [&]() {
      for (;;) {
        const int64_t start = next.fetch_add(grain);
        if (start >= end) break;
        const int64_t stop = std::min(end, start + grain);
        for (int64_t i = start; i < stop; ++i) body(i);
      }
    };
    if (internal::ThreadPool::Get().Run(threads - 1, worker)) return;
  }
#else
  (void)threads;
#endif
  for (int64_t i = begin; i < end; ++i) body(i);
}

// [begin, end) of chunk `c` when `n` items are cut into `chunks` nearly equal
// contiguous chunks.
inline void ChunkRange(int64_t n, int64_t chunks, int64_t c, int64_t* begin, int64_t* end) {
  *begin = n * c / chunks;
  *end = n * (c + 1) / chunks;
}

}  // namespace casual3d
