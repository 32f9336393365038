#include "format/parallel.h"

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace casual3d {
namespace {

TEST(ParallelTest, EveryIndexRunsOnce) {
  for (int threads : {1, 2, 3, 8}) {
    for (int64_t grain : {1, 7, 1000}) {
      std::vector<std::atomic<int>> hits(5000);
      ParallelFor(3, 5000, threads, [&](int64_t i) { hits[i].fetch_add(1); }, grain);
      for (int64_t i = 0; i < 5000; ++i) {
        ASSERT_EQ(hits[i].load(), i < 3 ? 0 : 1) << threads << " threads, grain " << grain;
      }
    }
  }
  int calls = 0;
  ParallelFor(5, 5, 4, [&](int64_t) { ++calls; });
  ParallelFor(5, 2, 4, [&](int64_t) { ++calls; });
  EXPECT_EQ(calls, 0);
}

// A loop inside a loop, and loops from two callers at once, run on their
// caller's thread instead of waiting for the busy pool.
TEST(ParallelTest, NestedAndConcurrentLoopsFinish) {
  std::atomic<int64_t> sum(0);
  ParallelFor(0, 16, 4, [&](int64_t i) {
    ParallelFor(0, 100, 4, [&](int64_t j) { sum.fetch_add(i * 100 + j); });
  });
  EXPECT_EQ(sum.load(), 1599 * 1600 / 2);
  std::atomic<int64_t> a(0), b(0);
  std::thread other([&] {
    for (int r = 0; r < 50; ++r) ParallelFor(0, 1000, 3, [&](int64_t i) { a.fetch_add(i); });
  });
  for (int r = 0; r < 50; ++r) ParallelFor(0, 1000, 3, [&](int64_t i) { b.fetch_add(i); });
  other.join();
  EXPECT_EQ(a.load(), 50 * 999 * 1000 / 2);
  EXPECT_EQ(b.load(), 50 * 999 * 1000 / 2);
}

TEST(ParallelTest, ResolveThreads) {
  EXPECT_EQ(ResolveThreads(3), 3);
  EXPECT_GE(ResolveThreads(0), 1);
  EXPECT_EQ(ResolveThreads(-2), ResolveThreads(0));
}

TEST(ParallelTest, ChunksCoverTheRangeInOrder) {
  for (int64_t n : {0, 1, 7, 100}) {
    int64_t next = 0;
    for (int64_t c = 0; c < 6; ++c) {
      int64_t begin, end;
      ChunkRange(n, 6, c, &begin, &end);
      EXPECT_EQ(begin, next);
      EXPECT_LE(begin, end);
      next = end;
    }
    EXPECT_EQ(next, n);
  }
}

}  // namespace
}  // namespace casual3d
