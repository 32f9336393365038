#include "reconstruct/pipeline/coverage.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "reconstruct/depth/parallel.h"

namespace casual3d::pipeline {
namespace {

// Solid angle of one pixel of row y of a width x height equirectangular image.
double RowSteradians(int y, int width, int height) {
  const double lat = (0.5 - (y + 0.5) / height) * kPi;
  return std::cos(lat) * (2.0 * kPi / width) * (kPi / height);
}

struct ProjectedView {
  Eigen::Matrix3d R_pano_to_cam;  // Rotation from the panorama frame to the camera.
  Eigen::Vector3d t;              // Camera-frame position of the panorama centre.
  double fx, fy, cx, cy;
  int width, height;
};

}  // namespace

Image8 FieldOfViewMask(const TwoLayerPanorama& pano, int layer,
                       const std::vector<CoverageView>& views, double reference_depth_m,
                       int num_threads, double* used_reference_depth_m) {
  if (layer < 0 || layer >= kNumLayers) throw std::invalid_argument("coverage: no such layer");
  const int W = pano.width(), H = pano.height();
  const LayerData& data = pano.layer(layer);
  if (!(reference_depth_m > 0)) {
    std::vector<float> depths;
    for (size_t i = 0; i < data.present.size(); ++i)
      if (data.present[i]) depths.push_back(data.depth_m[i]);
    reference_depth_m = 1.0;
    if (!depths.empty()) {
      std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
      reference_depth_m = depths[depths.size() / 2];
    }
  }
  if (used_reference_depth_m) *used_reference_depth_m = reference_depth_m;

  // World point of panorama direction d at depth r: centre + R_frame^T (r d).
  // Camera point: R_cam (centre + R_frame^T r d) + t_cam.
  const PanoramaFrame& frame = pano.frame();
  Eigen::Matrix3d R_frame;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R_frame(r, c) = frame.rotation[3 * r + c];
  const Eigen::Vector3d centre(frame.centre[0], frame.centre[1], frame.centre[2]);
  std::vector<ProjectedView> projected;
  for (const CoverageView& v : views) {
    const geometry::Camera pinhole = v.camera.PinholePart();
    ProjectedView p;
    p.R_pano_to_cam = v.pose.R() * R_frame.transpose();
    p.t = v.pose.WorldToCamera(centre);
    p.fx = pinhole.FocalX();
    p.fy = pinhole.FocalY();
    p.cx = pinhole.PrincipalX();
    p.cy = pinhole.PrincipalY();
    p.width = pinhole.width;
    p.height = pinhole.height;
    projected.push_back(p);
  }

  // Where the layer has no node: the depth of the nearest node (a hole's
  // surroundings, or the footprint's edge, say best how far the photos' rays
  // reach there), or the reference depth when the layer is empty.
  cv::Mat nearest_label;
  std::vector<float> label_depth;
  if (!data.present.empty() &&
      std::find(data.present.begin(), data.present.end(), 1) != data.present.end()) {
    cv::Mat absent(H, W, CV_8U);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        absent.at<uint8_t>(y, x) = data.present[pano.index(x, y)] ? 0 : 255;
    cv::Mat distance;
    cv::distanceTransform(absent, distance, nearest_label, cv::DIST_L2, cv::DIST_MASK_5,
                          cv::DIST_LABEL_PIXEL);
    // Labels number the zero (present) pixels 1, 2, ... in row-major order.
    label_depth.push_back(static_cast<float>(reference_depth_m));
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        if (data.present[pano.index(x, y)]) label_depth.push_back(data.depth_m[pano.index(x, y)]);
  }

  Image8 mask(W, H, 1, 0);
  depth::ParallelFor(
      0, H, depth::ResolveThreads(num_threads),
      [&](int64_t y64) {
        const int y = static_cast<int>(y64);
        size_t last_hit = 0;  // Neighbouring pixels usually fall in the same photo.
        for (int x = 0; x < W; ++x) {
          const size_t i = pano.index(x, y);
          double r = reference_depth_m;
          if (data.present[i]) {
            r = data.depth_m[i];
          } else if (!label_depth.empty()) {
            const int label = nearest_label.at<int>(y, x);
            if (label > 0 && label < static_cast<int>(label_depth.size())) r = label_depth[label];
          }
          const Vec3d d = EquirectPixelToDirection(x + 0.5, y + 0.5, W, H);
          const Eigen::Vector3d ray(d.x * r, d.y * r, d.z * r);
          for (size_t k = 0; k < projected.size(); ++k) {
            const ProjectedView& p = projected[(last_hit + k) % projected.size()];
            const Eigen::Vector3d q = p.R_pano_to_cam * ray + p.t;
            if (!(q.z() > 0)) continue;
            const double u = p.fx * q.x() / q.z() + p.cx;
            const double v = p.fy * q.y() / q.z() + p.cy;
            if (u >= 0 && v >= 0 && u <= p.width && v <= p.height) {
              mask.at(x, y) = 255;
              last_hit = (last_hit + k) % projected.size();
              break;
            }
          }
        }
      },
      4);
  return mask;
}

CoverageStats MeasureHoles(const TwoLayerPanorama& pano, int layer, const Image8& fov,
                           Image8* holes_out) {
  if (layer < 0 || layer >= kNumLayers) throw std::invalid_argument("coverage: no such layer");
  const int W = pano.width(), H = pano.height();
  if (fov.width() != W || fov.height() != H || fov.channels() != 1)
    throw std::invalid_argument("coverage: the field-of-view mask is not the panorama's size");
  const LayerData& data = pano.layer(layer);
  CoverageStats stats;
  double covered_sr = 0.0;
  for (int y = 0; y < H; ++y) {
    const double sr = RowSteradians(y, W, H);
    for (int x = 0; x < W; ++x) {
      if (!fov.at(x, y)) continue;
      ++stats.fov_pixels;
      stats.fov_steradians += sr;
      if (data.present[pano.index(x, y)]) covered_sr += sr;
    }
  }
  if (holes_out) *holes_out = Image8(W, H, 1, 0);
  if (stats.fov_pixels == 0) return stats;
  stats.covered_fraction = covered_sr / stats.fov_steradians;

  // Flood fill of uncovered field-of-view pixels (explicit stack; columns wrap).
  std::vector<uint8_t> seen(static_cast<size_t>(W) * H, 0);
  std::vector<int64_t> stack;
  const auto is_hole = [&](int x, int y) {
    return fov.at(x, y) != 0 && !data.present[pano.index(x, y)];
  };
  double largest_sr = 0.0, largest_interior_sr = 0.0;
  for (int y0 = 0; y0 < H; ++y0) {
    for (int x0 = 0; x0 < W; ++x0) {
      const size_t start = pano.index(x0, y0);
      if (seen[start] || !is_hole(x0, y0)) continue;
      seen[start] = 1;
      stack.assign(1, static_cast<int64_t>(start));
      int64_t pixels = 0;
      double sr = 0.0;
      bool touches_border = false;
      while (!stack.empty()) {
        const int64_t i = stack.back();
        stack.pop_back();
        const int x = static_cast<int>(i % W), y = static_cast<int>(i / W);
        ++pixels;
        sr += RowSteradians(y, W, H);
        if (holes_out) holes_out->at(x, y) = 255;
        const int nx[4] = {WrapColumn(x - 1, W), WrapColumn(x + 1, W), x, x};
        const int ny[4] = {y, y, y - 1, y + 1};
        for (int k = 0; k < 4; ++k) {
          if (ny[k] < 0 || ny[k] >= H) {
            touches_border = true;  // The pole rows end the field of view.
            continue;
          }
          if (!fov.at(nx[k], ny[k])) {
            touches_border = true;
            continue;
          }
          const size_t j = pano.index(nx[k], ny[k]);
          if (seen[j] || data.present[j]) continue;
          seen[j] = 1;
          stack.push_back(static_cast<int64_t>(j));
        }
      }
      ++stats.num_holes;
      stats.hole_pixels += pixels;
      if (sr > largest_sr) {
        largest_sr = sr;
        stats.largest_hole_pixels = pixels;
      }
      if (!touches_border) {
        ++stats.num_interior_holes;
        largest_interior_sr = std::max(largest_interior_sr, sr);
      }
    }
  }
  stats.largest_hole_fraction = largest_sr / stats.fov_steradians;
  stats.largest_interior_hole_fraction = largest_interior_sr / stats.fov_steradians;
  return stats;
}

CoverageStats MeasureCoverage(const TwoLayerPanorama& pano, int layer,
                              const std::vector<CoverageView>& views, int num_threads,
                              Image8* fov_out, Image8* holes) {
  double reference = 0.0;
  Image8 fov = FieldOfViewMask(pano, layer, views, 0.0, num_threads, &reference);
  CoverageStats stats = MeasureHoles(pano, layer, fov, holes);
  stats.reference_depth_m = reference;
  if (fov_out) *fov_out = std::move(fov);
  return stats;
}

}  // namespace casual3d::pipeline
