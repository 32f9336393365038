#include "reconstruct/depth/dense_free_space.h"

#include <chrono>
#include <string>
#include <utility>

#include "reconstruct/util/log.h"

namespace casual3d::depth {

std::shared_ptr<const ImageF> AfterMoves(std::shared_ptr<const ImageF> map, const std::vector<RoundMoves>& rounds,
                                         int i, int num_rounds) {
  bool any = false;
  for (int r = 0; r < num_rounds; ++r) any = any || !rounds[r][i].empty();
  if (!any) return map;
  auto moved = std::make_shared<ImageF>(*map);
  for (int r = 0; r < num_rounds; ++r)
    for (const DepthReplacement& m : rounds[r][i]) moved->data()[m.index] = m.depth;
  return moved;
}

std::vector<int> FreeSpaceViews(const LoadedWorkspace& ws, int i, int max_views) {
  // CheckFreeSpace's own choice among the neighbours: ref skipped, the
  // first max_views of the others.
  std::vector<int> views = {i};
  for (int j : ws.ranked_neighbors[i]) {
    if (j == i) continue;
    if (static_cast<int>(views.size()) > max_views) break;
    views.push_back(j);
  }
  return views;
}

int FreeSpaceCacheCapacity(const VisibilityFilterOptions& options) { return 2 * (1 + options.max_views); }

FreeSpaceResult CheckFreeSpaceRounds(const DensePlan& plan, const std::vector<CostVolume>& shells,
                                     const VisibilityFilterOptions& options, int threads,
                                     const ImageCache::Loader& depth, const ImageCache::Loader& gray_full) {
  const LoadedWorkspace& ws = plan.ws;
  const int n = plan.size();
  const int capacity = FreeSpaceCacheCapacity(options);
  FreeSpaceResult result;
  result.stats.resize(n);
  result.seconds.assign(n, 0.0);
  ImageCache grays(capacity, gray_full);  // The photos are the same in every round.
  int64_t depth_reads = 0;
  util::Progress progress("dense: free-space check", static_cast<int64_t>(n) * options.rounds);
  for (int round = 0; round < options.rounds; ++round) {
    ImageCache maps(capacity, [&](int j) { return AfterMoves(depth(j), result.rounds, j, round); });
    RoundMoves moves(n);
    ForEachPhoto(plan, AllPhotos(n), threads, [&](int i) {
      const auto t0 = std::chrono::steady_clock::now();
      // CheckFreeSpace on photo i's views alone, i at 0 and the others in
      // rank order: the views it reads, in its order, so the same result
      // as with every photo's arrays.
      const std::vector<int> views = FreeSpaceViews(ws, i, options.max_views);
      const int m = static_cast<int>(views.size());
      std::vector<std::shared_ptr<const ImageF>> held;
      std::vector<PinholeCamera> cameras(m);
      std::vector<const PinholeCamera*> camera_ptrs(m);
      std::vector<const ImageF*> depth_ptrs(m), gray_ptrs(m);
      std::vector<int> others;
      for (int k = 0; k < m; ++k) {
        const int j = views[k];
        held.push_back(maps.Get(j));
        depth_ptrs[k] = held.back().get();
        held.push_back(grays.Get(j));
        gray_ptrs[k] = held.back().get();
        cameras[k] = ws.views[j].camera_full.Resized(depth_ptrs[k]->width(), depth_ptrs[k]->height());
        camera_ptrs[k] = &cameras[k];
        if (k > 0) others.push_back(k);
      }
      const LabelGrid grid{shells[i].inv_near, shells[i].inv_far, shells[i].num_labels};
      moves[i] = CheckFreeSpace(0, camera_ptrs, depth_ptrs, gray_ptrs, others, grid.InvStep(), options,
                                &result.stats[i]);
      result.seconds[i] += SecondsSince(t0);
      progress.Advance();
    });
    result.rounds.push_back(std::move(moves));
    depth_reads += maps.loads();
  }
  progress.Finish();
  util::LogInfo("dense: the free-space check read " + std::to_string(grays.loads()) + " grey images and " +
                std::to_string(depth_reads) + " depth maps for " + std::to_string(n) + " photos and " +
                std::to_string(options.rounds) + " rounds");
  return result;
}

}  // namespace casual3d::depth
