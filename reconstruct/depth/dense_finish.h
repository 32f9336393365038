#pragma once

// Pass 3 of the dense stage (dense_passes.h): the free-space check of every
// final depth map against the others (dense_free_space.h), then OUT/depth/,
// the evaluation against ground truth, the cross-view consistency and
// OUT/dense.json.
//
// Its full-resolution inputs are read photo by photo through FinishInputs,
// so that it needs the memory of the photos in flight and of their
// neighbours, not of every photo: RunDenseStage lends the maps and images it
// holds, a finish unit (dense_units.h) reads them from files, and both run
// the same code with the same outputs.

#include <chrono>
#include <string>
#include <vector>

#include "reconstruct/depth/dense_passes.h"
#include "reconstruct/depth/image_cache.h"

namespace casual3d::depth {

// Where pass 3 reads photo i's full-resolution images, each when it needs
// them (possibly several times, from several threads at once).
struct FinishInputs {
  // The depth map pass 2 returned (before the free-space check).
  ImageCache::Loader depth;
  // The grey image DenseView::gray_full (ReadViewGrayFull reads the same).
  ImageCache::Loader gray_full;
  // The ground-truth depth map, empty where there is none; only called with
  // DenseOptions::ground_truth_dir.
  ImageCache::Loader ground_truth;
};

// Inputs lent, not copied, from `depth` and `ground_truth` (per photo) and
// the grey images of plan.ws, which must have its pixels (LoadViewPixels);
// all three must outlive the FinishDense call.
FinishInputs LendFinishInputs(const DensePlan& plan, const std::vector<ImageF>& depth,
                              const std::vector<ImageF>& ground_truth);

// Pass 3 over all photos: `inputs` as above, `photos` from pass 2, `shells`
// from pass 1. Writes OUT/depth/ and OUT/dense.json; returns the report,
// whose seconds_total runs from `start` and seconds_load is `seconds_load`.
// Throws the first photo's error, named by the photo.
DenseReport FinishDense(const DensePlan& plan, const DenseOptions& options, const FinishInputs& inputs,
                        std::vector<PhotoReport> photos, const std::vector<CostVolume>& shells,
                        const std::string& out_dir, std::chrono::steady_clock::time_point start,
                        double seconds_load);

}  // namespace casual3d::depth
