#pragma once

// The order of the one-process dense stage's per-photo work (dense_stage.h).
// A photo's depth pass reads its own cost cache and the WTA maps of the
// photos it needs (SweepsNeeded), so it can run as soon as those photos are
// swept, and its cost cache (about 1 GB per photo at 2048x1024) can go the
// moment it is done. Sweeping the photos in an order that completes one
// photo's needs after another keeps a few caches on disk at a time instead
// of every photo's (docs/DECISIONS.md, "Dense: each photo's depth as soon as
// its neighbours are swept").

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "reconstruct/depth/dense_passes.h"

namespace casual3d::depth {

struct DenseSchedule {
  std::vector<int> sweep_order;          // Every photo once.
  std::vector<std::vector<int>> needs;   // Per photo: SweepsNeeded.
  // Most cost caches on disk at once when the photos run one at a time in
  // sweep_order, each depth pass as soon as its needs are swept.
  int peak_caches = 0;
};

// Greedy: while photos are left, take the photo whose depth pass misses the
// fewest sweeps (the lowest index among equals) and sweep what it misses, in
// index order. Deterministic.
DenseSchedule ScheduleDense(const DensePlan& plan, const DenseOptions& options);

// Bytes of photo i's cost cache (cost_cache.h): 16-bit costs per pixel and
// label, and a float photo weight per pixel, at working resolution.
uint64_t CostCacheBytes(const DensePlan& plan, int i);

// The cost caches on disk at once with `outer` photos in flight: the largest
// ones, peak_caches + outer - 1 of them (at most every photo's).
struct CacheNeed {
  int count = 0;
  uint64_t bytes = 0;
};

// Returns what the schedule needs; throws std::runtime_error naming
// `cache_dir` when its file system has less free space than that.
CacheNeed CheckCacheSpace(const DensePlan& plan, const DenseSchedule& schedule, int outer,
                          const std::string& cache_dir);

// Runs sweep(i) and depth(i) for every photo on `outer` threads: each thread
// takes a depth pass whose needs are swept when there is one (the lowest
// photo index first), else the next sweep of schedule.sweep_order, unless
// peak_caches + outer - 1 photos are swept or sweeping without their depth
// pass done (the caches that CheckCacheSpace counts). depth(i) starts only
// after sweep(j) for every j in needs[i] has returned.
// After a failure no new work starts; the first error, named by its photo,
// is thrown as std::runtime_error once the running work has returned.
void RunScheduled(const DensePlan& plan, const DenseSchedule& schedule, int outer,
                  const std::function<void(int)>& sweep, const std::function<void(int)>& depth);

}  // namespace casual3d::depth
