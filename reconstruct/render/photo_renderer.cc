#include "reconstruct/render/photo_renderer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/parallel_for.h"

namespace casual3d::render {
namespace {

// Canvas sides are limited to this many times the photo's side (strong
// distortion can send corner rays very far out) and to the renderer's limit.
constexpr double kMaxCanvasScale = 3.0;
constexpr int kMaxCanvasSide = 16384;
// Extra canvas pixels around the undistorted rays, for bilinear neighbours.
constexpr int kCanvasMargin = 2;

}  // namespace

RenderResult RenderPhotoView(const Mesh& mesh, ImageView<const uint8_t> atlas,
                             const PanoramaFrame& frame, const geometry::Camera& camera,
                             const geometry::Pose& pose, const RenderOptions& options) {
  PinholeView view = ViewFromPhoto(camera, pose, frame);  // Validates the camera.
  if (!camera.HasDistortion()) return RenderMesh(mesh, atlas, view, options);

  const int width = camera.width, height = camera.height;
  const double fx = camera.FocalX(), fy = camera.FocalY();
  const double cx = camera.PrincipalX(), cy = camera.PrincipalY();
  // Undistorted pinhole coordinates of photo pixel (i + 0.5, j + 0.5).
  auto undistorted = [&](double x, double y) {
    const Eigen::Vector3d ray = camera.Unproject(Eigen::Vector2d(x, y));
    return Eigen::Vector2d(fx * ray.x() + cx, fy * ray.y() + cy);
  };

  // The canvas: the bounding box of the undistorted rays of the photo's
  // border pixels and of a coarse interior grid.
  double x_min = 0.0, x_max = width, y_min = 0.0, y_max = height;
  auto include = [&](double x, double y) {
    const Eigen::Vector2d q = undistorted(x, y);
    if (!q.allFinite()) return;
    x_min = std::min(x_min, q.x());
    x_max = std::max(x_max, q.x());
    y_min = std::min(y_min, q.y());
    y_max = std::max(y_max, q.y());
  };
  for (int i = 0; i < width; ++i) {
    include(i + 0.5, 0.5);
    include(i + 0.5, height - 0.5);
  }
  for (int j = 0; j < height; ++j) {
    include(0.5, j + 0.5);
    include(width - 0.5, j + 0.5);
  }
  for (int j = 0; j < height; j += 16) {
    for (int i = 0; i < width; i += 16) include(i + 0.5, j + 0.5);
  }
  const double max_w = std::min<double>(kMaxCanvasSide, kMaxCanvasScale * width);
  const double max_h = std::min<double>(kMaxCanvasSide, kMaxCanvasScale * height);
  // Keep the canvas centred on the photo when it has to be limited.
  const double grow_x = std::min(std::max(-x_min, x_max - width), (max_w - width) / 2);
  const double grow_y = std::min(std::max(-y_min, y_max - height), (max_h - height) / 2);
  const int pad_x = static_cast<int>(std::ceil(std::max(0.0, grow_x))) + kCanvasMargin;
  const int pad_y = static_cast<int>(std::ceil(std::max(0.0, grow_y))) + kCanvasMargin;
  view.width = width + 2 * pad_x;
  view.height = height + 2 * pad_y;
  view.cx = cx + pad_x;
  view.cy = cy + pad_y;
  if (view.width > kMaxCanvasSide || view.height > kMaxCanvasSide) {
    throw std::invalid_argument("camera " + std::to_string(camera.camera_id) + ": image size " +
                                std::to_string(width) + "x" + std::to_string(height) +
                                " is too large to render with its distortion");
  }
  const RenderResult canvas = RenderMesh(mesh, atlas, view, options);

  RenderResult result;
  result.color = Image8(width, height, 3);
  result.depth = ImageF(width, height, 1, 0.0f);
  result.mask = Image8(width, height, 1, 0);
  auto resample_row = [&](int j) {
    for (int i = 0; i < width; ++i) {
      uint8_t* out = &result.color.at(i, j, 0);
      for (int c = 0; c < 3; ++c) out[c] = options.background[c];
      const Eigen::Vector2d q = undistorted(i + 0.5, j + 0.5);
      if (!q.allFinite()) continue;
      const double qx = q.x() + pad_x, qy = q.y() + pad_y;
      if (!(qx >= 0.0 && qy >= 0.0 && qx < view.width && qy < view.height)) continue;
      const int nx = static_cast<int>(qx), ny = static_cast<int>(qy);
      if (canvas.mask.at(nx, ny) == 0) continue;
      result.mask.at(i, j) = 255;
      result.depth.at(i, j) = canvas.depth.at(nx, ny);
      // Bilinear over the covered neighbours only.
      const double sx = qx - 0.5, sy = qy - 0.5;
      const int x0 = static_cast<int>(std::floor(sx)), y0 = static_cast<int>(std::floor(sy));
      const double ax = sx - x0, ay = sy - y0;
      double sum[3] = {0, 0, 0}, weight = 0.0;
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const int x = x0 + dx, y = y0 + dy;
          if (x < 0 || y < 0 || x >= view.width || y >= view.height) continue;
          if (canvas.mask.at(x, y) == 0) continue;
          const double w = (dx ? ax : 1.0 - ax) * (dy ? ay : 1.0 - ay);
          for (int c = 0; c < 3; ++c) sum[c] += w * canvas.color.at(x, y, c);
          weight += w;
        }
      }
      if (weight <= 0.0) {  // Only the nearest pixel itself has weight 0.
        for (int c = 0; c < 3; ++c) out[c] = canvas.color.at(nx, ny, c);
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        out[c] = static_cast<uint8_t>(std::clamp(std::lround(sum[c] / weight), 0L, 255L));
      }
    }
  };
  base::ParallelFor(0, height, base::ResolveThreads(options.num_threads),
                    [&](int64_t j) { resample_row(static_cast<int>(j)); });
  for (size_t k = 0; k < result.mask.size(); ++k)
    result.covered_pixels += result.mask.data()[k] != 0;
  return result;
}

}  // namespace casual3d::render
