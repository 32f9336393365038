#include "reconstruct/depth/dense_schedule.h"

#include <algorithm>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <set>
#include <stdexcept>

#include "base/parallel_for.h"

namespace casual3d::depth {
namespace fs = std::filesystem;
namespace {

// Per photo j, the photos whose depth pass needs j's sweep; and per photo,
// how many of its needs are not swept yet (all of them).
struct NeedCounts {
  std::vector<std::vector<int>> needed_by;
  std::vector<int> missing;
};

NeedCounts CountNeeds(const std::vector<std::vector<int>>& needs) {
  NeedCounts c;
  c.needed_by.resize(needs.size());
  for (size_t i = 0; i < needs.size(); ++i) {
    c.missing.push_back(static_cast<int>(needs[i].size()));
    for (int j : needs[i]) c.needed_by[j].push_back(static_cast<int>(i));
  }
  return c;
}

}  // namespace

DenseSchedule ScheduleDense(const DensePlan& plan, const DenseOptions& options) {
  const int n = plan.size();
  DenseSchedule s;
  for (int i = 0; i < n; ++i) s.needs.push_back(SweepsNeeded(plan, options, i));
  auto [needed_by, missing] = CountNeeds(s.needs);
  std::vector<bool> swept(n, false), done(n, false);
  int on_disk = 0, left = n;
  while (left > 0) {
    int best = -1;
    for (int i = 0; i < n; ++i)
      if (!done[i] && (best < 0 || missing[i] < missing[best])) best = i;
    std::vector<int> todo;
    for (int j : s.needs[best])
      if (!swept[j]) todo.push_back(j);
    std::sort(todo.begin(), todo.end());
    for (int j : todo) {
      swept[j] = true;
      s.sweep_order.push_back(j);
      s.peak_caches = std::max(s.peak_caches, ++on_disk);
      // Every photo whose needs are now all swept (its own among them) runs
      // its depth pass and frees its cache.
      for (int i : needed_by[j]) {
        if (--missing[i] > 0) continue;
        done[i] = true;
        --on_disk;
        --left;
      }
    }
  }
  return s;
}

uint64_t CostCacheBytes(const DensePlan& plan, int i) {
  const PinholeCamera& c = plan.ws.views[i].camera;
  const uint64_t pixels = static_cast<uint64_t>(c.width) * static_cast<uint64_t>(c.height);
  return pixels * static_cast<uint64_t>(plan.num_labels[i]) * 2 + pixels * 4;
}

CacheNeed CheckCacheSpace(const DensePlan& plan, const DenseSchedule& schedule, int outer,
                          const std::string& cache_dir) {
  std::vector<uint64_t> bytes;
  for (int i = 0; i < plan.size(); ++i) bytes.push_back(CostCacheBytes(plan, i));
  std::sort(bytes.rbegin(), bytes.rend());
  CacheNeed need;
  need.count = static_cast<int>(std::min(bytes.size(), static_cast<size_t>(schedule.peak_caches + outer - 1)));
  for (int k = 0; k < need.count; ++k) need.bytes += bytes[k];
  std::error_code ec;
  const fs::space_info space = fs::space(cache_dir, ec);
  if (ec || space.available >= need.bytes) return need;  // Unknown free space: let the writes tell.
  char msg[512];
  std::snprintf(msg, sizeof(msg),
                "%s: the dense stage needs %.1f GB of free disk for %zu cost caches at once, and %.1f GB are "
                "free; free some space, or lower the working resolution (dense --scale, reconstruct "
                "--working-megapixels)",
                cache_dir.c_str(), need.bytes / 1e9, static_cast<size_t>(need.count), space.available / 1e9);
  throw std::runtime_error(msg);
}

void RunScheduled(const DensePlan& plan, const DenseSchedule& schedule, int outer,
                  const std::function<void(int)>& sweep, const std::function<void(int)>& depth) {
  const int n = plan.size();
  NeedCounts counts = CountNeeds(schedule.needs);
  std::mutex mutex;
  std::condition_variable changed;
  std::set<int> ready;  // Photos whose depth pass may run, lowest first.
  size_t next_sweep = 0;
  int running = 0, depths_done = 0;
  // Cost caches started and not yet freed. A sweep waits while the schedule's
  // peak is reached with the other threads' work: otherwise a slow sweep
  // early in the order holds back the depth passes that need it while the
  // other threads sweep on. Never a deadlock: with nothing running, the
  // caches left are those of the sequential schedule, fewer than its peak.
  const int max_live = schedule.peak_caches + std::max(1, outer) - 1;
  int live = 0;
  auto may_sweep = [&] { return next_sweep < schedule.sweep_order.size() && live < max_live; };
  std::string first_error;
  base::ParallelFor(0, std::max(1, outer), std::max(1, outer), [&](int64_t) {
    std::unique_lock<std::mutex> lock(mutex);
    while (true) {
      int photo = -1;
      bool is_sweep = false;
      changed.wait(lock, [&] {
        return !first_error.empty() || !ready.empty() || may_sweep() || running == 0;
      });
      if (!first_error.empty()) return;
      if (!ready.empty()) {
        photo = *ready.begin();
        ready.erase(ready.begin());
      } else if (may_sweep()) {
        photo = schedule.sweep_order[next_sweep++];
        is_sweep = true;
        ++live;
      } else {
        // Nothing to start and nothing running: every depth pass has run
        // (or a need was never swept, which ScheduleDense rules out).
        if (depths_done < n && first_error.empty())
          first_error = "dense: " + std::to_string(n - depths_done) + " photos were never ready";
        changed.notify_all();
        return;
      }
      ++running;
      lock.unlock();
      std::string error;
      try {
        (is_sweep ? sweep : depth)(photo);
      } catch (const std::exception& e) {
        error = plan.ws.views[photo].name + ": " + e.what();
      } catch (...) {
        error = plan.ws.views[photo].name + ": unknown error";
      }
      lock.lock();
      --running;
      if (!error.empty() && first_error.empty()) first_error = error;
      if (error.empty() && is_sweep) {
        for (int i : counts.needed_by[photo])
          if (--counts.missing[i] == 0) ready.insert(i);
      } else if (error.empty()) {
        ++depths_done;
        --live;
      }
      changed.notify_all();
    }
  });
  if (!first_error.empty()) throw std::runtime_error(first_error);
}

}  // namespace casual3d::depth
