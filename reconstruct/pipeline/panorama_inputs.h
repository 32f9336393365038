#pragma once

// The panorama stage's inputs (panorama_stage.h): the undistorted photos of a
// sparse model with their cameras, poses and depth maps, and the finite depth
// given to the sky.

#include <string>
#include <vector>

#include "format/image.h"
#include "reconstruct/geometry/camera.h"
#include "reconstruct/geometry/colmap_model.h"

namespace casual3d::pipeline {

struct PanoramaPhoto {
  Image8 rgb;    // SPARSE/images/<name>.
  ImageF depth;  // DEPTH/depth/<stem>.exr, channel Z, metres along the optical axis.
  geometry::Camera camera;
  geometry::Pose pose;
};

// The photos of `model` (read from `sparse_dir`/sparse), in the model's
// order, with their depth maps from `depth_dir`/depth. Throws
// std::runtime_error naming the file for a missing camera, a camera with lens
// distortion (the stage needs the sparse stage's undistorted photos), a
// missing depth map or an empty model.
std::vector<PanoramaPhoto> LoadPanoramaPhotos(const geometry::SparseModel& model,
                                              const std::string& sparse_dir,
                                              const std::string& depth_dir);

// Gives the sky (non-finite or non-positive depth) of every photo a finite
// depth beyond everything else: `sky_depth_m` when > 0, else 1.5 times the
// largest finite depth of all photos (1000 when none). Returns that depth.
double FillSkyDepth(double sky_depth_m, std::vector<PanoramaPhoto>* photos);

}  // namespace casual3d::pipeline
