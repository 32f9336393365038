#include "base/parallel_for.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace casual3d::base {
namespace {

TEST(ParallelForTest, EveryIndexOfTheRangeRunsOnce) {
  for (int threads : {1, 2, 3, 8}) {
    for (int64_t grain : {1, 7, 1000, 10000}) {
      std::vector<std::atomic<int>> hits(5000);
      ParallelFor(
          3, 5000, threads, [&](int64_t i) { hits[i].fetch_add(1); }, grain);
      for (int64_t i = 0; i < 5000; ++i)
        ASSERT_EQ(hits[i].load(), i < 3 ? 0 : 1) << threads << " threads, grain " << grain;
    }
  }
  // Negative bounds, a single index, and empty or reversed ranges.
  std::atomic<int64_t> sum(0);
  ParallelFor(-10, 10, 4, [&](int64_t i) { sum.fetch_add(i); });
  EXPECT_EQ(sum.load(), -10);
  std::atomic<int> calls(0);
  ParallelFor(7, 8, 4, [&](int64_t i) { calls.fetch_add(i == 7 ? 1 : 100); });
  EXPECT_EQ(calls.load(), 1);
  ParallelFor(5, 5, 4, [&](int64_t) { calls.fetch_add(1); });
  ParallelFor(5, 2, 4, [&](int64_t) { calls.fetch_add(1); });
  ParallelFor(
      0, 3, 4, [&](int64_t) { calls.fetch_add(1); }, 0);  // A grain below 1 counts as 1.
  EXPECT_EQ(calls.load(), 4);
}

TEST(ParallelForTest, OneThreadRunsInOrderOnTheCaller) {
  for (int threads : {1, 0, -3}) {
    std::vector<int64_t> order;
    const std::thread::id caller = std::this_thread::get_id();
    bool on_caller = true;
    ParallelFor(0, 100, threads, [&](int64_t i, int thread) {
      order.push_back(i);
      on_caller = on_caller && std::this_thread::get_id() == caller && thread == 0;
    });
    ASSERT_EQ(order.size(), 100u);
    for (int64_t i = 0; i < 100; ++i) EXPECT_EQ(order[i], i);
    EXPECT_TRUE(on_caller) << threads;
  }
}

TEST(ParallelForTest, ThreadNumbersIndexScratchPerThread) {
  const int threads = 4;
  std::vector<int64_t> per_thread(threads, 0);  // Each slot written by one thread only.
  std::atomic<bool> in_range(true);
  ParallelFor(
      0, 100000, threads,
      [&](int64_t i, int thread) {
        if (thread < 0 || thread >= threads) {
          in_range = false;
          return;
        }
        per_thread[thread] += i;
      },
      64);
  EXPECT_TRUE(in_range.load());
  int64_t total = 0;
  for (int64_t s : per_thread) total += s;
  EXPECT_EQ(total, int64_t{99999} * 100000 / 2);
}

TEST(ParallelForTest, AnExceptionReachesTheCallerAndStopsTheLoop) {
  for (int threads : {1, 2, 4}) {
    std::atomic<int64_t> ran(0);
    try {
      ParallelFor(0, 1000000, threads, [&](int64_t i) {
        ran.fetch_add(1);
        if (i == 10) throw std::runtime_error("index 10 failed");
      });
      ADD_FAILURE() << "no exception with " << threads << " threads";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "index 10 failed");
    }
    // Indices after the failure are not started (those in flight finish).
    EXPECT_LT(ran.load(), 1000000) << threads;
    if (threads == 1) {
      EXPECT_EQ(ran.load(), 11);
    }
  }
}

struct CustomError {
  int index;
};

TEST(ParallelForTest, TheFirstOfSeveralExceptionsKeepsItsType) {
  try {
    ParallelFor(0, 64, 4, [&](int64_t i) { throw CustomError{static_cast<int>(i)}; });
    ADD_FAILURE() << "no exception";
  } catch (const CustomError& e) {
    EXPECT_GE(e.index, 0);
    EXPECT_LT(e.index, 64);
  }
}

// Threads are started per call, so an inner loop gets threads of its own and
// an exception thrown inside it crosses both loops.
TEST(ParallelForTest, NestedLoops) {
  std::atomic<int64_t> sum(0);
  ParallelFor(0, 8, 2, [&](int64_t i) {
    ParallelFor(0, 100, 2, [&](int64_t j) { sum.fetch_add(i * 100 + j); });
  });
  EXPECT_EQ(sum.load(), int64_t{799} * 800 / 2);
  EXPECT_THROW(ParallelFor(0, 4, 2,
                           [&](int64_t i) {
                             ParallelFor(0, 50, 2, [&](int64_t j) {
                               if (i == 3 && j == 20) throw std::out_of_range("inner");
                             });
                           }),
               std::out_of_range);
}

TEST(ParallelForTest, ResolveThreads) {
  EXPECT_EQ(ResolveThreads(3), 3);
  EXPECT_GE(ResolveThreads(0), 1);
  EXPECT_EQ(ResolveThreads(-1), ResolveThreads(0));
}

}  // namespace
}  // namespace casual3d::base
