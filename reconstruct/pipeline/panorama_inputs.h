#pragma once

// The panorama stage's inputs (panorama_stage.h): the undistorted photos of a
// sparse model with their cameras, poses and depth maps, and the finite depth
// given to the sky. The photos' pixels are read one photo at a time, when
// the stage warps it, so that a capture of any size needs the memory of the
// photos in flight and of the warps (a photo and its depth map of 8192x4096
// are 230 MB: 23 GB for 100 photos).

#include <atomic>
#include <exception>
#include <mutex>
#include <string>
#include <vector>

#include "base/parallel_for.h"
#include "format/image.h"
#include "reconstruct/geometry/camera.h"
#include "reconstruct/geometry/colmap_model.h"

namespace casual3d::pipeline {

struct PanoramaPhoto {
  std::string rgb_path;    // SPARSE/images/<name>.
  std::string depth_path;  // DEPTH/depth/<stem>.exr, channel Z, metres along the optical axis.
  geometry::Camera camera;
  geometry::Pose pose;
};

// The photos of `model` (read from `sparse_dir`/sparse), in the model's
// order, with the paths of their images and depth maps (in `depth_dir`/depth)
// but not their pixels. Throws std::runtime_error naming the file for a
// missing camera, a camera with lens distortion (the stage needs the sparse
// stage's undistorted photos), a missing depth map or an empty model, the
// first photo in model order that has one.
std::vector<PanoramaPhoto> LoadPanoramaPhotos(const geometry::SparseModel& model,
                                              const std::string& sparse_dir,
                                              const std::string& depth_dir);

// A photo's pixels: its image (3 channels, sRGB) and its depth map.
struct PanoramaPixels {
  Image8 rgb;
  ImageF depth;
};

// Reads `photo`'s image and depth map. Throws naming the file that cannot be
// read.
PanoramaPixels ReadPanoramaPixels(const PanoramaPhoto& photo);

// The depth given to the sky: `sky_depth_m` when > 0, else 1.5 times the
// largest finite depth of all photos' maps (1000 when none), which reads
// every map once, one per thread at a time. Throws as ReadPanoramaPixels
// (ForEachPanoramaPhoto).
double SkyDepth(double sky_depth_m, const std::vector<PanoramaPhoto>& photos, int num_threads);

// Gives the sky of `depth` (non-finite or non-positive depth) the finite
// depth `sky_m`, beyond everything else.
void FillSky(double sky_m, ImageF* depth);

// Runs body(i) for each photo i in [0, n) on `num_threads` threads (0: all
// cores). When photos fail, throws the error of the first in model order, as
// a loop in that order would: a failure at i keeps the photos after i from
// starting, while those before it, all started (ParallelFor takes the
// indices in order), run to their end.
template <typename Body>
void ForEachPanoramaPhoto(int n, int num_threads, Body&& body) {
  std::mutex mutex;
  std::exception_ptr error;
  std::atomic<int64_t> first_failed{n};
  base::ParallelFor(0, n, base::ResolveThreads(num_threads), [&](int64_t i) {
    if (i > first_failed.load()) return;
    try {
      body(static_cast<int>(i));
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      if (i < first_failed.load()) {
        first_failed.store(i);
        error = std::current_exception();
      }
    }
  });
  if (error) std::rethrow_exception(error);
}

}  // namespace casual3d::pipeline
