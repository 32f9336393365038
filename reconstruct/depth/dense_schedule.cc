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

DenseSchedule ScheduleDense(const DensePlan& plan, const DenseOptions& options) {
  const int n = plan.size();
  DenseSchedule s;
  s.needs.resize(n);
  std::vector<std::vector<int>> needed_by(n);
  for (int i = 0; i < n; ++i) {
    s.needs[i] = SweepsNeeded(plan, options, i);
    for (int j : s.needs[i]) needed_by[j].push_back(i);
  }
  std::vector<int> missing(n);
  for (int i = 0; i < n; ++i) missing[i] = static_cast<int>(s.needs[i].size());
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
      for (int i : needed_by[j]) --missing[i];
      // Every photo whose needs are now all swept runs its depth pass and
      // frees its cache.
      for (int i = 0; i < n; ++i) {
        if (done[i] || missing[i] > 0 || !swept[i]) continue;
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

void CheckCacheSpace(const DensePlan& plan, const DenseSchedule& schedule, int outer,
                     const std::string& cache_dir) {
  std::vector<uint64_t> bytes;
  for (int i = 0; i < plan.size(); ++i) bytes.push_back(CostCacheBytes(plan, i));
  std::sort(bytes.rbegin(), bytes.rend());
  const size_t count = std::min(bytes.size(), static_cast<size_t>(schedule.peak_caches + outer - 1));
  uint64_t need = 0;
  for (size_t k = 0; k < count; ++k) need += bytes[k];
  std::error_code ec;
  const fs::space_info space = fs::space(cache_dir, ec);
  if (ec || space.available >= need) return;
  char msg[512];
  std::snprintf(msg, sizeof(msg),
                "%s: the dense stage needs %.1f GB of free disk for %zu cost caches at once, and %.1f GB are "
                "free; free some space, or lower the working resolution (dense --scale, reconstruct "
                "--working-megapixels)",
                cache_dir.c_str(), need / 1e9, count, space.available / 1e9);
  throw std::runtime_error(msg);
}

void RunScheduled(const DensePlan& plan, const DenseSchedule& schedule, int outer,
                  const std::function<void(int)>& sweep, const std::function<void(int)>& depth) {
  const int n = plan.size();
  std::vector<std::vector<int>> needed_by(n);
  std::vector<int> missing(n);
  for (int i = 0; i < n; ++i) {
    missing[i] = static_cast<int>(schedule.needs[i].size());
    for (int j : schedule.needs[i]) needed_by[j].push_back(i);
  }
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
        for (int i : needed_by[photo])
          if (--missing[i] == 0) ready.insert(i);
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
