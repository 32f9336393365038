#include "reconstruct/depth/workspace.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/io/cv_bridge.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/sfm/scene_setup.h"

namespace casual3d::depth {
namespace fs = std::filesystem;

namespace {

ImageF ToFloat(const Image8& rgb) {
  ImageF out(rgb.width(), rgb.height(), 3);
  for (size_t i = 0; i < rgb.size(); ++i) out.data()[i] = rgb.data()[i] * (1.0f / 255.0f);
  return out;
}

// View i's photo as decoded, its size checked against its camera's.
Image8 ReadViewPhoto(const LoadedWorkspace& ws, int i) {
  const DenseView& v = ws.views.at(i);
  const std::string path = (fs::path(ws.images_dir) / v.name).string();
  Image8 rgb = io::ReadImage(path);
  if (rgb.width() != v.full_width || rgb.height() != v.full_height)
    throw std::runtime_error(path + ": size " + std::to_string(rgb.width()) + "x" +
                             std::to_string(rgb.height()) + " does not match its camera (" +
                             std::to_string(v.full_width) + "x" + std::to_string(v.full_height) + ")");
  return rgb;
}

// View i's photo as RGB float in [0, 1].
ImageF ReadViewFloat(const LoadedWorkspace& ws, int i) { return ToFloat(ReadViewPhoto(ws, i)); }

}  // namespace

ImageF ReadPhotoFloat(const std::string& path) { return ToFloat(io::ReadImage(path)); }

ImageF ResizeArea(const ImageF& image, int width, int height) {
  if (image.width() == width && image.height() == height) return image;
  ImageF out(width, height, image.channels());
  cv::Mat dst = io::ToMat(out);
  cv::resize(io::ToMat(image), dst, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  return out;
}

ImageF GrayOf(const ImageF& rgb) {
  ImageF gray(rgb.width(), rgb.height(), 1);
  for (size_t i = 0; i < static_cast<size_t>(rgb.width()) * rgb.height(); ++i) {
    const float* c = rgb.data() + 3 * i;
    gray.data()[i] = 0.299f * c[0] + 0.587f * c[1] + 0.114f * c[2];
  }
  return gray;
}

std::string OutputStem(const std::string& image_name) {
  std::string stem = image_name;
  const size_t slash = stem.find_last_of('/');
  const size_t dot = stem.find_last_of('.');
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) stem.resize(dot);
  std::replace(stem.begin(), stem.end(), '/', '_');
  std::replace(stem.begin(), stem.end(), '\\', '_');
  return stem;
}

void CheckViewPhoto(const LoadedWorkspace& ws, int i) { ReadViewPhoto(ws, i); }

// LoadViewPixels and ReadViewGrayFull both make the full-resolution grey
// image as GrayOf(ReadViewFloat(...)), so that the free-space check, which
// reads it on demand, sees the bytes the depth pass saw.
ImageF ReadViewGrayFull(const LoadedWorkspace& ws, int i) { return GrayOf(ReadViewFloat(ws, i)); }

void LoadViewPixels(LoadedWorkspace* ws, int i) {
  DenseView& v = ws->views.at(i);
  if (HasViewPixels(*ws, i)) return;
  const ImageF full = ReadViewFloat(*ws, i);
  // All three or none, so that a failure leaves the view without pixels.
  ImageF gray_full = GrayOf(full);
  ImageF color = ResizeArea(full, v.camera.width, v.camera.height);
  v.gray = GrayOf(color);
  v.color = std::move(color);
  v.gray_full = std::move(gray_full);
}

bool HasViewPixels(const LoadedWorkspace& ws, int i) { return !ws.views.at(i).gray_full.empty(); }

LoadedWorkspace LoadWorkspace(const std::string& workspace_dir, double working_scale,
                              const NeighborOptions& neighbor_options, bool load_pixels) {
  if (!(working_scale > 0 && working_scale <= 1))
    throw std::invalid_argument("working_scale must lie in (0, 1]");
  const fs::path root(workspace_dir);
  if (!fs::is_directory(root))
    throw std::runtime_error(workspace_dir + ": not a directory (expected a workspace with images/ and sparse/)");
  const fs::path sparse = root / "sparse";
  const fs::path images = root / "images";
  if (!fs::is_directory(sparse))
    throw std::runtime_error(sparse.string() + ": missing; run the sparse stage (or casual3d synth) first");
  if (!fs::is_directory(images)) throw std::runtime_error(images.string() + ": missing photo folder");

  const geometry::SparseModel model = geometry::ReadModel(sparse.string());
  if (model.images.size() < 2)
    throw std::runtime_error(sparse.string() + ": the model has " + std::to_string(model.images.size()) +
                             " registered photos; the dense stage needs at least 2");

  std::map<int, sfm::DepthRange> ranges;
  for (const fs::path& p : {sparse / "depth_ranges.json", root / "depth_ranges.json"}) {
    if (fs::exists(p)) {
      ranges = sfm::ReadDepthRanges(p.string());
      break;
    }
  }
  if (ranges.empty()) ranges = sfm::ComputeDepthRanges(model, sfm::DepthRangeOptions());

  LoadedWorkspace ws;
  ws.images_dir = images.string();
  std::vector<const geometry::ModelImage*> ordered;
  for (const auto& [id, im] : model.images) ordered.push_back(&im);
  std::sort(ordered.begin(), ordered.end(),
            [](const auto* a, const auto* b) { return a->name < b->name; });

  std::vector<NeighborInput> nin;
  for (const geometry::ModelImage* im : ordered) {
    auto cam_it = model.cameras.find(im->camera_id);
    if (cam_it == model.cameras.end())
      throw std::runtime_error(sparse.string() + ": image " + im->name + " refers to missing camera " +
                               std::to_string(im->camera_id));
    const geometry::Camera& cam = cam_it->second;
    if (cam.model != geometry::CameraModelId::kPinhole &&
        cam.model != geometry::CameraModelId::kSimplePinhole && cam.HasDistortion())
      throw std::runtime_error(sparse.string() + ": camera " + std::to_string(cam.camera_id) +
                               " has lens distortion; the dense stage needs undistorted (PINHOLE) photos");
    auto range_it = ranges.find(im->image_id);
    if (range_it == ranges.end())
      throw std::runtime_error(sparse.string() + ": no depth range for " + im->name);

    DenseView v;
    v.name = im->name;
    v.full_width = cam.width;
    v.full_height = cam.height;
    PinholeCamera pc;
    pc.width = cam.width;
    pc.height = cam.height;
    pc.fx = cam.FocalX();
    pc.fy = cam.FocalY();
    pc.cx = cam.PrincipalX();
    pc.cy = cam.PrincipalY();
    pc.R = im->pose.R();
    pc.t = im->pose.translation;
    const int ww = std::max(8, static_cast<int>(std::lround(cam.width * working_scale)));
    const int wh = std::max(8, static_cast<int>(std::lround(cam.height * working_scale)));
    v.camera = pc.Resized(ww, wh);
    v.camera_full = pc;
    v.range.near_m = range_it->second.near_m;
    v.range.far_m = range_it->second.far_m;
    ws.views.push_back(std::move(v));
    if (load_pixels) LoadViewPixels(&ws, static_cast<int>(ws.views.size()) - 1);

    NeighborInput in;
    in.center = im->pose.Center();
    in.direction = im->pose.ViewingDirection();
    for (const auto& ob : im->points2d)
      if (ob.point3d_id != geometry::kInvalidPoint3DId)
        in.point_ids.push_back(static_cast<long long>(ob.point3d_id));
    nin.push_back(std::move(in));
  }
  // Tracks also say who sees what (some writers leave points2d empty).
  std::map<int, int> index_of_image;
  for (size_t i = 0; i < ordered.size(); ++i) index_of_image[ordered[i]->image_id] = static_cast<int>(i);
  for (const auto& [id, p] : model.points)
    for (const auto& te : p.track) {
      auto it = index_of_image.find(te.image_id);
      if (it != index_of_image.end()) nin[it->second].point_ids.push_back(static_cast<long long>(id));
    }
  std::vector<std::pair<long long, Eigen::Vector3d>> pts;
  pts.reserve(model.points.size());
  for (const auto& [id, p] : model.points) pts.emplace_back(static_cast<long long>(id), p.xyz);
  ws.ranked_neighbors = RankNeighbors(nin, pts, neighbor_options);
  return ws;
}

}  // namespace casual3d::depth
