#include "reconstruct/synth/render_photo.h"

#include <cmath>
#include <limits>
#include <vector>

#include "base/parallel_for.h"
#include "reconstruct/synth/procedural_texture.h"
#include "reconstruct/synth/srgb.h"

namespace casual3d::synth {
namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

struct CameraRays {
  Eigen::Matrix3d cam_to_world;
  Eigen::Vector3d centre;
  double fx, fy, cx, cy;

  // Unit world direction through continuous pixel (u, v) and its camera-frame Z component.
  Eigen::Vector3d Direction(double u, double v, double* z_component) const {
    const Eigen::Vector3d d_cam((u - cx) / fx, (v - cy) / fy, 1.0);
    const double norm = d_cam.norm();
    *z_component = 1.0 / norm;
    return cam_to_world * (d_cam / norm);
  }
};

Eigen::Vector3d Sample(const Scene& scene, const CameraRays& rays, double u, double v,
                       double pixel_angle, Hit* hit_out, double* depth_out) {
  double z_component;
  const Eigen::Vector3d dir = rays.Direction(u, v, &z_component);
  Hit hit;
  if (!scene.TraceClosest(rays.centre, dir, 1e-6, &hit)) {
    if (hit_out) hit_out->primitive = -1;
    if (depth_out) *depth_out = std::numeric_limits<double>::infinity();
    return scene.Sky(dir);
  }
  if (hit_out) *hit_out = hit;
  if (depth_out) *depth_out = hit.t * z_component;
  return scene.Shade(hit, rays.centre, dir, pixel_angle);
}

}  // namespace

PhotoRender RenderPhoto(const Scene& scene, const geometry::Camera& camera,
                        const geometry::Pose& pose, const RenderOptions& options) {
  const int w = camera.width, h = camera.height;
  CameraRays rays;
  rays.cam_to_world = pose.R().transpose();
  rays.centre = -(rays.cam_to_world * pose.translation);
  rays.fx = camera.FocalX();
  rays.fy = camera.FocalY();
  rays.cx = camera.PrincipalX();
  rays.cy = camera.PrincipalY();
  const double pixel_angle = 1.0 / std::max(rays.fx, rays.fy);

  PhotoRender out;
  out.radiance = ImageF(w, h, 3);
  out.depth_m = ImageF(w, h, 1);
  std::vector<int> surface(static_cast<size_t>(w) * h);

  // Pass 1: one ray through each pixel centre.
  base::ParallelFor(0, h, base::ResolveThreads(options.num_threads), [&](int64_t y64) {
    const int y = static_cast<int>(y64);
    for (int x = 0; x < w; ++x) {
      Hit hit;
      double depth;
      const Eigen::Vector3d c = Sample(scene, rays, x + 0.5, y + 0.5, pixel_angle, &hit, &depth);
      for (int k = 0; k < 3; ++k) out.radiance.at(x, y, k) = static_cast<float>(c[k]);
      out.depth_m.at(x, y) = std::isinf(depth) ? kInfF : static_cast<float>(depth);
      surface[static_cast<size_t>(y) * w + x] = hit.primitive < 0 ? -1 : hit.SurfaceId();
    }
  });

  // Pass 2: supersample pixels on a surface boundary. The decision reads only
  // pass-1 results, so it is the same for any thread partition.
  const int n = options.edge_samples;
  std::vector<int> edges_per_row(h, 0);
  if (n > 1) {
    base::ParallelFor(0, h, base::ResolveThreads(options.num_threads), [&](int64_t y64) {
      const int y = static_cast<int>(y64);
      for (int x = 0; x < w; ++x) {
        const int s = surface[static_cast<size_t>(y) * w + x];
        const bool edge = (x > 0 && surface[static_cast<size_t>(y) * w + x - 1] != s) ||
                          (x + 1 < w && surface[static_cast<size_t>(y) * w + x + 1] != s) ||
                          (y > 0 && surface[static_cast<size_t>(y - 1) * w + x] != s) ||
                          (y + 1 < h && surface[static_cast<size_t>(y + 1) * w + x] != s);
        if (!edge) continue;
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int j = 0; j < n; ++j) {
          for (int i = 0; i < n; ++i) {
            sum += Sample(scene, rays, x + (i + 0.5) / n, y + (j + 0.5) / n, pixel_angle, nullptr,
                          nullptr);
          }
        }
        sum /= n * n;
        for (int k = 0; k < 3; ++k) out.radiance.at(x, y, k) = static_cast<float>(sum[k]);
        ++edges_per_row[y];
      }
    });
  }
  for (int c : edges_per_row) out.edge_pixels += c;
  return out;
}

Image8 Develop(const ImageF& radiance, const DevelopOptions& options) {
  // The sRGB curve tabulated on 16384 linear steps and interpolated (error
  // below 0.01 code values): the exact curve costs a pow() per channel.
  constexpr int kTable = 16384;
  static const std::vector<double> table = [] {
    std::vector<double> t(kTable + 2);
    for (int i = 0; i <= kTable + 1; ++i) t[i] = 255.0 * LinearToSrgb(static_cast<double>(i) / kTable);
    return t;
  }();
  Image8 photo(radiance.width(), radiance.height(), 3);
  for (int y = 0; y < radiance.height(); ++y) {
    for (int x = 0; x < radiance.width(); ++x) {
      // Approximately Gaussian noise: the sum of four 16-bit uniforms of one
      // hash, centred and scaled to unit variance (Irwin-Hall).
      const uint64_t key = Hash(options.seed, y, x);
      for (int c = 0; c < 3; ++c) {
        const double linear =
            std::min(1.0, std::max(0.0, static_cast<double>(radiance.at(x, y, c)) * options.exposure));
        const double pos = linear * kTable;
        const int i = static_cast<int>(pos);
        double v = table[i] + (table[i + 1] - table[i]) * (pos - i);
        if (options.noise_sigma > 0) {
          const uint64_t h = Hash(key, c);
          const double sum = static_cast<double>(h & 0xFFFF) + static_cast<double>((h >> 16) & 0xFFFF) +
                             static_cast<double>((h >> 32) & 0xFFFF) + static_cast<double>(h >> 48);
          v += options.noise_sigma * (sum / 65536.0 - 2.0) * 1.7320508075688772;
        }
        photo.at(x, y, c) = static_cast<uint8_t>(std::lround(std::min(255.0, std::max(0.0, v))));
      }
    }
  }
  return photo;
}

}  // namespace casual3d::synth
