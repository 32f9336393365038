#include "reconstruct/pipeline/coverage.h"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "base/parallel_for.h"

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
  const LayerData& data = pano.layer(layer);
  ImageF depth(pano.width(), pano.height(), 1, 0.0f);
  // Depth > 0 marks a node; a valid panorama's nodes all have one.
  for (size_t i = 0; i < data.present.size(); ++i)
    if (data.present[i]) depth.data()[i] = data.depth_m[i];
  return FieldOfViewMask(depth, pano.frame(), views, reference_depth_m, num_threads,
                         used_reference_depth_m);
}

Image8 FieldOfViewMask(const ImageF& depth_m, const PanoramaFrame& frame,
                       const std::vector<CoverageView>& views, double reference_depth_m,
                       int num_threads, double* used_reference_depth_m) {
  const int W = depth_m.width(), H = depth_m.height();
  if (depth_m.channels() != 1 || W != 2 * H)
    throw std::invalid_argument("coverage: the depth is not a one-channel equirectangular image");
  // The layer's nodes: pixels with a depth above 0.
  const float* depth = depth_m.data();
  const size_t num_pixels = static_cast<size_t>(W) * H;
  const auto index = [W](int x, int y) { return static_cast<size_t>(y) * W + x; };
  if (!(reference_depth_m > 0)) {
    std::vector<float> depths;
    for (size_t i = 0; i < num_pixels; ++i)
      if (depth[i] > 0) depths.push_back(depth[i]);
    reference_depth_m = 1.0;
    if (!depths.empty()) {
      std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
      reference_depth_m = depths[depths.size() / 2];
    }
  }
  if (used_reference_depth_m) *used_reference_depth_m = reference_depth_m;

  // World point of panorama direction d at depth r: centre + R_frame^T (r d).
  // Camera point: R_cam (centre + R_frame^T r d) + t_cam.
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
  if (std::any_of(depth, depth + num_pixels, [](float d) { return d > 0; })) {
    cv::Mat absent(H, W, CV_8U);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) absent.at<uint8_t>(y, x) = depth[index(x, y)] > 0 ? 0 : 255;
    cv::Mat distance;
    cv::distanceTransform(absent, distance, nearest_label, cv::DIST_L2, cv::DIST_MASK_5,
                          cv::DIST_LABEL_PIXEL);
    // Labels number the zero (present) pixels 1, 2, ... in row-major order.
    label_depth.push_back(static_cast<float>(reference_depth_m));
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        if (depth[index(x, y)] > 0) label_depth.push_back(depth[index(x, y)]);
  }

  Image8 mask(W, H, 1, 0);
  base::ParallelFor(
      0, H, base::ResolveThreads(num_threads),
      [&](int64_t y64) {
        const int y = static_cast<int>(y64);
        size_t last_hit = 0;  // Neighbouring pixels usually fall in the same photo.
        for (int x = 0; x < W; ++x) {
          const size_t i = index(x, y);
          double r = reference_depth_m;
          if (depth[i] > 0) {
            r = depth[i];
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

Image8 FootprintMask(const std::vector<warp::WarpedView>& warps, int width, int height) {
  Image8 mask(width, height, 1, 0);
  for (const warp::WarpedView& w : warps) {
    const warp::WarpedLayer& f = w.front;
    for (int cy = 0; cy < f.height(); ++cy) {
      const int y = f.y0 + cy;
      if (y < 0 || y >= height) continue;
      for (int cx = 0; cx < f.width(); ++cx)
        if (f.depth_m.at(cx, cy) > 0) mask.at(WrapColumn(f.x0 + cx, width), y) = 255;
    }
  }
  return mask;
}

int64_t FillGapsInside(const Image8& mask, Image8* rgb, ImageF* depth_m, Image<int16_t>* label) {
  const int W = depth_m->width(), H = depth_m->height();
  if (mask.width() != W || mask.height() != H || rgb->width() != W || rgb->height() != H ||
      rgb->channels() != 3 || (label && !label->empty() && (label->width() != W || label->height() != H)))
    throw std::invalid_argument("coverage: gap filling needs images of one size");
  const bool with_label = label && !label->empty();
  float* depth = depth_m->data();
  uint8_t* color = rgb->data();
  const auto gap = [&](int64_t i) { return mask.data()[i] != 0 && !(depth[i] > 0); };
  // Calls visit(j) for the 8-neighbours j of pixel i (columns wrap, rows end).
  const auto for_each_neighbour = [W, H](int64_t i, auto&& visit) {
    const int x = static_cast<int>(i % W), y = static_cast<int>(i / W);
    for (int yy = std::max(0, y - 1); yy <= std::min(H - 1, y + 1); ++yy)
      for (int dx = -1; dx <= 1; ++dx)
        if (dx != 0 || yy != y) visit(static_cast<int64_t>(yy) * W + WrapColumn(x + dx, W));
  };
  // The farthest filled 8-neighbour of i, or -1; of equally far ones a
  // 4-neighbour (so that the mirrored colours below continue straight).
  const auto farthest_neighbour = [&](int64_t i) {
    int64_t best = -1;
    bool best_straight = false;
    for_each_neighbour(i, [&](int64_t j) {
      if (!(depth[j] > 0)) return;
      const bool straight = j / W == i / W || j % W == i % W;
      if (best < 0 || depth[j] > depth[best] || (depth[j] == depth[best] && straight && !best_straight)) {
        best = j;
        best_straight = straight;
      }
    });
    return best;
  };
  // Pixels with content before the filling, and for each filled pixel the
  // pixel of its rim its chain of sources started from.
  std::vector<uint8_t> original(static_cast<size_t>(W) * H, 0);
  for (int64_t i = 0; i < static_cast<int64_t>(W) * H; ++i) original[i] = depth[i] > 0;
  std::vector<int64_t> origin(static_cast<size_t>(W) * H, -1);
  // The original pixel mirrored from i through its rim pixel o, if it shows
  // the surface i continues (within 5% of depth d), else -1: the texture
  // beside the rim continues into the gap instead of streaks of one colour.
  const auto mirrored = [&](int64_t i, int64_t o, float d) -> int64_t {
    const int x = static_cast<int>(i % W), y = static_cast<int>(i / W);
    const int ox = static_cast<int>(o % W), oy = static_cast<int>(o / W);
    int dx = ox - x;
    if (dx > W / 2) dx -= W;
    if (dx < -W / 2) dx += W;
    const int my = oy + (oy - y);
    if (my < 0 || my >= H) return -1;
    const int64_t m = static_cast<int64_t>(my) * W + WrapColumn(ox + dx, W);
    if (!original[m] || std::abs(depth[m] - d) > 0.05f * d) return -1;
    return m;
  };

  // Ring 0: gap pixels next to a filled one, each with its source.
  std::vector<uint8_t> queued(static_cast<size_t>(W) * H, 0);
  std::vector<std::pair<int64_t, int64_t>> ring, next;  // (pixel, its source)
  for (int64_t i = 0; i < static_cast<int64_t>(W) * H; ++i) {
    if (!gap(i)) continue;
    const int64_t source = farthest_neighbour(i);
    if (source < 0) continue;
    ring.emplace_back(i, source);
    queued[i] = 1;
  }
  std::vector<std::array<uint8_t, 3>> fills;
  int64_t filled = 0;
  while (!ring.empty()) {
    // Colour: the mean of the filled neighbours within 5% of the source's
    // depth (a smooth extension of the background, not streaks of one
    // pixel's colour).
    fills.clear();
    for (const auto& [i, source] : ring) {
      const int64_t rim = original[source] ? source : origin[source];
      origin[i] = rim;
      if (const int64_t m = rim >= 0 ? mirrored(i, rim, depth[source]) : -1; m >= 0) {
        fills.push_back({color[3 * m], color[3 * m + 1], color[3 * m + 2]});
        continue;
      }
      const float limit = 0.95f * depth[source];
      float sum[3] = {0, 0, 0};
      int count = 0;
      for_each_neighbour(i, [&](int64_t j) {
        if (!(depth[j] >= limit)) return;
        for (int c = 0; c < 3; ++c) sum[c] += color[3 * j + c];
        ++count;
      });
      std::array<uint8_t, 3> mean;
      for (int c = 0; c < 3; ++c) mean[c] = static_cast<uint8_t>(std::lround(sum[c] / count));
      fills.push_back(mean);
    }
    // Written after the whole ring is chosen, so a ring only grows from the previous ones.
    for (size_t k = 0; k < ring.size(); ++k) {
      const auto [i, source] = ring[k];
      depth[i] = depth[source];
      for (int c = 0; c < 3; ++c) color[3 * i + c] = fills[k][c];
      if (with_label) label->data()[i] = label->data()[source];
    }
    filled += static_cast<int64_t>(ring.size());
    // The next ring: unqueued gap pixels next to this one, with their sources.
    next.clear();
    for (const auto& [i, source] : ring) {
      for_each_neighbour(i, [&](int64_t j) {
        if (queued[j] || !gap(j)) return;
        queued[j] = 1;
        next.emplace_back(j, -1);
      });
    }
    for (auto& [j, source] : next) source = farthest_neighbour(j);
    ring.swap(next);
  }
  return filled;
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

}  // namespace casual3d::pipeline
