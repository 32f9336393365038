#include "reconstruct/pipeline/panorama_inputs.h"

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
  util::Progress progress("panorama: loading photos", static_cast<int64_t>(model.images.size()));
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
    p.rgb = io::ReadImage((fs::path(sparse_dir) / "images" / image.name).string());
    const std::string depth_path =
        (fs::path(depth_dir) / "depth" / (depth::OutputStem(image.name) + ".exr")).string();
    if (!fs::exists(depth_path)) {
      throw std::runtime_error(depth_path + ": missing depth map for photo " + image.name +
                               " (run the dense stage first)");
    }
    p.depth = io::ReadExrChannels(depth_path, {"Z"});
    photos.push_back(std::move(p));
    progress.Advance();
  }
  if (photos.empty()) throw std::runtime_error(sparse_dir + "/sparse: the model has no photos");
  return photos;
}

double FillSkyDepth(double sky_depth_m, std::vector<PanoramaPhoto>* photos) {
  double sky = sky_depth_m;
  if (sky <= 0) {
    float far = 0;
    for (const PanoramaPhoto& p : *photos)
      for (float d : p.depth.vector())
        if (std::isfinite(d) && d > far) far = d;
    sky = far > 0 ? 1.5 * far : 1000.0;
  }
  for (PanoramaPhoto& p : *photos) {
    for (float& d : p.depth.vector())
      if (!std::isfinite(d) || d <= 0) d = static_cast<float>(sky);
  }
  return sky;
}

}  // namespace casual3d::pipeline
