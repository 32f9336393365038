#pragma once

// Pass 3's free-space check (visibility_filter.h) of every photo's final
// depth map against its neighbours', reading the full-resolution maps and
// grey images photo by photo, so that a capture of any size is checked in
// the memory of the photos in flight and their neighbours rather than of
// every photo (a map and a grey image are 268 MB at 8192x4096: 27 GB for
// 100 photos).
//
// A round checks every photo against the maps as the earlier rounds left
// them and applies its replacements only once all are checked, so the
// result depends neither on the photos' order nor on the threads. Only the
// replacements are kept between rounds: a map as round r reads it is its
// pass-2 map with rounds 0 .. r-1's replacements applied in round order.

#include <memory>
#include <vector>

#include "reconstruct/depth/dense_passes.h"
#include "reconstruct/depth/image_cache.h"
#include "reconstruct/depth/visibility_filter.h"

namespace casual3d::depth {

// One round's replacements, per photo, in increasing pixel order.
using RoundMoves = std::vector<std::vector<DepthReplacement>>;

struct FreeSpaceResult {
  std::vector<RoundMoves> rounds;      // [round][photo].
  std::vector<VisibilityStats> stats;  // Per photo, summed over the rounds.
  std::vector<double> seconds;         // Per photo, summed over the rounds.
};

// `map` (photo i's pass-2 map) after the replacements of the first
// `num_rounds` rounds of `rounds`, applied in round order: `map` itself when
// there are none, else a copy.
std::shared_ptr<const ImageF> AfterMoves(std::shared_ptr<const ImageF> map, const std::vector<RoundMoves>& rounds,
                                         int i, int num_rounds);

// The views CheckFreeSpace reads for photo i: i, then the first max_views
// of its ranked neighbours other than i, best first.
std::vector<int> FreeSpaceViews(const LoadedWorkspace& ws, int i, int max_views);

// Images each of the check's caches keeps beyond those in use: two photos'
// views, so that the next photo in order finds most of its neighbours.
int FreeSpaceCacheCapacity(const VisibilityFilterOptions& options);

// options.rounds rounds of the check over every photo with `threads`
// threads, photo i's label step from shells[i]. `depth` gives a photo's
// pass-2 map and `gray_full` its full-resolution grey image (the same size),
// each read when a check needs it and kept in an ImageCache of
// FreeSpaceCacheCapacity images. Throws the first photo's error, named by
// the photo (ForEachPhoto).
FreeSpaceResult CheckFreeSpaceRounds(const DensePlan& plan, const std::vector<CostVolume>& shells,
                                     const VisibilityFilterOptions& options, int threads,
                                     const ImageCache::Loader& depth, const ImageCache::Loader& gray_full);

}  // namespace casual3d::depth
