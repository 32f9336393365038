#pragma once

// The dense stage's three passes (dense_stage.h), each a function over one
// photo or over all, so that RunDenseStage can run them in one process with
// the results in memory and dense_units.h as separate processes with the
// results on disk, with the same outputs:
//   1. sweep:  a photo's cost volume (written to its cost cache) and WTA map;
//              reads the photo and its swept neighbours;
//   2. depth:  the photo's anchors (GC filter against its neighbours' WTA
//              maps), near envelope, MRF, sub-label steps, upsampling and
//              full-resolution steps; writes OUT/confidence/ and OUT/envelope/
//              and returns the full-resolution depth map;
//   3. finish: the free-space check of every map against the others, then
//              OUT/depth/, the evaluation, the cross-view consistency and
//              OUT/dense.json (dense_finish.h); reads the maps and the
//              full-resolution grey images photo by photo.

#include <chrono>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/parallel_for.h"
#include "reconstruct/depth/dense_stage.h"
#include "reconstruct/depth/huge_pages.h"
#include "reconstruct/depth/workspace.h"

namespace casual3d::depth {

// The loaded workspace and what every pass derives from it alone.
struct DensePlan {
  LoadedWorkspace ws;                  // Depth ranges with the far-plane extension applied.
  std::vector<int> num_labels;         // Per photo: labels swept.
  std::vector<std::vector<int>> swept; // Per photo: its swept neighbours, best first.
  double diag_ratio = 1.0;             // Working diagonal / DenseOptions::reference_diagonal.

  int size() const { return static_cast<int>(ws.views.size()); }
  std::vector<const DenseView*> SweptViews(int i) const;
};

// Loads the workspace (workspace.h; the photos' pixels only with
// `load_pixels`) and plans the sweep: the far-plane extension
// (DenseOptions::min_far_over_near) and each photo's neighbours. Throws as
// LoadWorkspace.
DensePlan PlanDense(const std::string& workspace_dir, const DenseOptions& options, bool load_pixels = true);

// The photos whose pixels passes 1 and 2 read for the photos `photos`: each
// one and its swept neighbours, sorted. (Pass 3 reads grey images on
// demand: dense_finish.h.)
std::vector<int> PhotosRead(const DensePlan& plan, const std::vector<int>& photos);

// The photos whose sweeps pass 2 reads for photo i: its own (cost cache and
// WTA map) and, for the GC filter's WTA maps, those of its first max_views
// ranked neighbours (gc_filter.h).
std::vector<int> SweepsNeeded(const DensePlan& plan, const DenseOptions& options, int i);

// The parts of photo i's report known before any pass runs.
PhotoReport PhotoHeader(const DensePlan& plan, int i);

// Pass 1 for photo i with `threads` threads: writes the cost volume to
// `cost_path` (cost_cache.h), stores the WTA map in `*wta` and returns the
// volume without its costs (sizes and depth grid).
CostVolume SweepPhoto(const DensePlan& plan, int i, const DenseOptions& options, int threads,
                      const std::string& cost_path, BufferPool* pool, ImageF* wta);

// The depth map <stem>.exr in `dir` (its "Z" or "depth" channel, else the
// first), such as a ground-truth map; empty if the file is missing.
ImageF ReadDepthMap(const std::string& dir, const std::string& stem);

// Pass 2 for photo i with `threads` threads. `wta` holds every photo's WTA
// map (only photo i's and those of the first gc.max_views of its ranked
// neighbours are read), `shell` photo i's SweepPhoto result, `ground_truth`
// photo i's ground truth (may be empty). Writes OUT/confidence/<stem>.exr,
// OUT/envelope/<stem>.exr (and OUT/debug/ with options.debug); fills `*pr`'s
// anchors, envelope, MRF and refinement fields; returns the depth map.
ImageF DepthPhoto(const DensePlan& plan, int i, const DenseOptions& options, int threads,
                  const std::vector<const ImageF*>& wta, const CostVolume& shell, const std::string& cost_path,
                  const ImageF& ground_truth, const std::string& out_dir, BufferPool* pool, PhotoReport* pr);

// Creates OUT/ and its depth/, confidence/, envelope/ (and debug/) folders.
void CreateDenseOutputFolders(const std::string& out_dir, const DenseOptions& options);

// Runs body(i) for each i in `photos`, `outer` at a time. A photo's failure
// does not stop the others; the first one, named by its photo, is thrown as
// std::runtime_error once all have run.
template <typename Body>
void ForEachPhoto(const DensePlan& plan, const std::vector<int>& photos, int outer, Body&& body) {
  std::mutex mutex;
  std::string first_error;
  base::ParallelFor(0, static_cast<int64_t>(photos.size()), outer, [&](int64_t k) {
    const int i = photos[k];
    try {
      body(i);
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex);
      if (first_error.empty()) first_error = plan.ws.views[i].name + ": " + e.what();
    }
  });
  if (!first_error.empty()) throw std::runtime_error(first_error);
}

// 0, 1, ..., n - 1.
std::vector<int> AllPhotos(int n);

// Seconds from `t0` to now (steady clock), for the report's timings.
double SecondsSince(std::chrono::steady_clock::time_point t0);

}  // namespace casual3d::depth
