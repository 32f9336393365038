#include "reconstruct/depth/dense_schedule.h"

#include <atomic>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

namespace casual3d::depth {
namespace {

// A plan of n photos on a ring: each photo's ranked neighbours are the
// nearest ones around it, nearer first.
DensePlan RingPlan(int n, int width = 64, int height = 32, int labels = 100) {
  DensePlan plan;
  plan.ws.views.resize(n);
  plan.ws.ranked_neighbors.resize(n);
  plan.num_labels.assign(n, labels);
  for (int i = 0; i < n; ++i) {
    plan.ws.views[i].name = "p" + std::to_string(i) + ".jpg";
    plan.ws.views[i].camera.width = width;
    plan.ws.views[i].camera.height = height;
    for (int d = 1; d <= n / 2; ++d) {
      plan.ws.ranked_neighbors[i].push_back((i + d) % n);
      if ((i + n - d) % n != (i + d) % n) plan.ws.ranked_neighbors[i].push_back((i + n - d) % n);
    }
  }
  return plan;
}

TEST(DenseScheduleTest, SweepsEveryPhotoOnceAndKeepsFewCaches) {
  DenseOptions options;
  options.gc.max_views = 4;
  const DensePlan plan = RingPlan(100);
  const DenseSchedule s = ScheduleDense(plan, options);
  ASSERT_EQ(s.sweep_order.size(), 100u);
  std::vector<int> seen(100, 0);
  for (int i : s.sweep_order) ++seen[i];
  for (int i = 0; i < 100; ++i) EXPECT_EQ(seen[i], 1) << i;
  ASSERT_EQ(s.needs[10], (std::vector<int>{10, 11, 9, 12, 8}));
  // Each depth pass needs its photo and 2 on either side: at most 5 caches
  // (the last photos of the ring close it, needing photo 0's neighbours).
  EXPECT_GE(s.peak_caches, 3);
  EXPECT_LE(s.peak_caches, 8);
  EXPECT_LT(s.peak_caches, 100);

  // Two rings of 50 photos, each photo's nearest neighbour on the other ring
  // (index +-50), as on a sphere rig: sweeping in index order would keep
  // every photo of the first ring until its partner is swept, 50 or more
  // caches; the schedule completes photos across both rings.
  DensePlan rings = RingPlan(100);
  for (int i = 0; i < 100; ++i) {
    const int ring = i / 50, k = i % 50;
    rings.ws.ranked_neighbors[i] = {(1 - ring) * 50 + k, ring * 50 + (k + 1) % 50, ring * 50 + (k + 49) % 50,
                                    (1 - ring) * 50 + (k + 1) % 50, (1 - ring) * 50 + (k + 49) % 50};
  }
  const DenseSchedule r = ScheduleDense(rings, options);
  EXPECT_LE(r.peak_caches, 12);

  options.use_gc_filter = false;  // Each photo needs only itself: one cache.
  EXPECT_EQ(ScheduleDense(plan, options).peak_caches, 1);
}

TEST(DenseScheduleTest, DepthRunsOnlyAfterItsNeedsAreSwept) {
  DenseOptions options;
  options.gc.max_views = 3;
  const DensePlan plan = RingPlan(24);
  const DenseSchedule s = ScheduleDense(plan, options);
  for (int outer : {1, 2, 4}) {
    std::mutex mutex;
    std::vector<int> swept(24, 0), depth_done(24, 0);
    int live = 0, peak = 0;
    RunScheduled(
        plan, s, outer,
        [&](int i) {
          std::this_thread::sleep_for(std::chrono::microseconds(200));
          std::lock_guard<std::mutex> lock(mutex);
          ++swept[i];
          peak = std::max(peak, ++live);
        },
        [&](int i) {
          std::lock_guard<std::mutex> lock(mutex);
          for (int j : s.needs[i]) EXPECT_EQ(swept[j], 1) << "photo " << i << " before sweep " << j;
          ++depth_done[i];
          --live;
        });
    for (int i = 0; i < 24; ++i) {
      EXPECT_EQ(swept[i], 1) << i;
      EXPECT_EQ(depth_done[i], 1) << i;
    }
    EXPECT_LE(peak, s.peak_caches + outer - 1) << outer << " threads";
  }
}

TEST(DenseScheduleTest, AFailureStopsNewWorkAndIsNamed) {
  DenseOptions options;
  const DensePlan plan = RingPlan(12);
  const DenseSchedule s = ScheduleDense(plan, options);
  std::atomic<int> depths{0};
  try {
    RunScheduled(
        plan, s, 2,
        [&](int i) {
          if (i == 5) throw std::runtime_error("cannot read the photo");
        },
        [&](int) { ++depths; });
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "p5.jpg: cannot read the photo");
  }
  // Photos needing photo 5's sweep never ran their depth pass.
  EXPECT_LT(depths.load(), 12);
}

TEST(DenseScheduleTest, CacheSpaceIsCheckedBeforeAnySweep) {
  DenseOptions options;
  const DensePlan small = RingPlan(8);
  EXPECT_EQ(CostCacheBytes(small, 0), 64u * 32u * 100u * 2u + 64u * 32u * 4u);
  const std::string dir = std::filesystem::temp_directory_path().string();
  CheckCacheSpace(small, ScheduleDense(small, options), 2, dir);  // A few hundred KB.
  // Photos of 1e6 x 1e5 pixels with 256 labels: 51 TB of costs each.
  const DensePlan huge = RingPlan(8, 1000000, 100000, 256);
  try {
    CheckCacheSpace(huge, ScheduleDense(huge, options), 2, dir);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(dir + ": the dense stage needs "), std::string::npos) << what;
    EXPECT_NE(what.find("GB are free; free some space, or lower the working resolution (dense --scale, "
                        "reconstruct --working-megapixels)"),
              std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace casual3d::depth
