#include "reconstruct/pipeline/panorama_inputs.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include "reconstruct/depth/workspace.h"
#include "reconstruct/io/exr_io.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/util/log.h"

namespace casual3d::pipeline {
namespace fs = std::filesystem;

std::vector<PanoramaPhoto> LoadPanoramaPhotos(const geometry::SparseModel& model,
                                              const std::string& sparse_dir,
                                              const std::string& depth_dir) {
  std::vector<PanoramaPhoto> photos;
  for (const auto& [id, image] : model.images) {
    PanoramaPhoto p;
    const auto cam = model.cameras.find(image.camera_id);
    if (cam == model.cameras.end()) {
      throw std::runtime_error(sparse_dir + "/sparse: image " + image.name +
                               " names a missing camera " + std::to_string(image.camera_id));
    }
    if (cam->second.HasDistortion()) {
      throw std::runtime_error(sparse_dir + "/sparse: camera " + std::to_string(image.camera_id) +
                               " has lens distortion; the panorama stage needs undistorted "
                               "photos (run the sparse stage)");
    }
    p.camera = cam->second;
    p.pose = image.pose;
    p.rgb_path = (fs::path(sparse_dir) / "images" / image.name).string();
    p.depth_path = (fs::path(depth_dir) / "depth" / (depth::OutputStem(image.name) + ".exr")).string();
    if (!fs::exists(p.depth_path)) {
      throw std::runtime_error(p.depth_path + ": missing depth map for photo " + image.name +
                               " (run the dense stage first)");
    }
    photos.push_back(std::move(p));
  }
  if (photos.empty()) throw std::runtime_error(sparse_dir + "/sparse: the model has no photos");
  return photos;
}

PanoramaPixels ReadPanoramaPixels(const PanoramaPhoto& photo) {
  PanoramaPixels p;
  p.rgb = io::ReadImage(photo.rgb_path);
  p.depth = io::ReadExrChannels(photo.depth_path, {"Z"});
  return p;
}

double SkyDepth(double sky_depth_m, const std::vector<PanoramaPhoto>& photos, int num_threads) {
  if (sky_depth_m > 0) return sky_depth_m;
  // The largest finite depth per photo, then of all: the same float
  // whatever the order.
  std::vector<float> far(photos.size(), 0.0f);
  util::Progress progress("panorama: depth of the sky", static_cast<int64_t>(photos.size()));
  ForEachPanoramaPhoto(static_cast<int>(photos.size()), num_threads, [&](int i) {
    const ImageF depth = io::ReadExrChannels(photos[i].depth_path, {"Z"});
    for (float d : depth.vector())
      if (std::isfinite(d) && d > far[i]) far[i] = d;
    progress.Advance();
  });
  progress.Finish();
  const float largest = far.empty() ? 0.0f : *std::max_element(far.begin(), far.end());
  return largest > 0 ? 1.5 * largest : 1000.0;
}

void FillSky(double sky_m, ImageF* depth) {
  for (float& d : depth->vector())
    if (!std::isfinite(d) || d <= 0) d = static_cast<float>(sky_m);
}

}  // namespace casual3d::pipeline
