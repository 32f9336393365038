#include "reconstruct/synth/ground_truth_panorama.h"

#include <cmath>
#include <limits>

#include "base/parallel_for.h"

namespace casual3d::synth {

const std::array<std::string, kNumPanoramaChannels>& PanoramaChannelNames() {
  static const std::array<std::string, kNumPanoramaChannels> kNames = {
      "front.R", "front.G", "front.B", "front.Z", "front.NX", "front.NY", "front.NZ",
      "back.R",  "back.G",  "back.B",  "back.Z",  "back.NX",  "back.NY",  "back.NZ"};
  return kNames;
}

GroundTruthPanorama RenderGroundTruthPanorama(const Scene& scene, const PanoramaFrame& frame,
                                              int width, int height, int num_threads) {
  GroundTruthPanorama out;
  out.frame = frame;
  out.pixels = ImageF(width, height, kNumPanoramaChannels);
  Eigen::Matrix3d world_to_pano;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) world_to_pano(r, c) = frame.rotation[3 * r + c];
  const Eigen::Matrix3d pano_to_world = world_to_pano.transpose();
  const Eigen::Vector3d centre(frame.centre[0], frame.centre[1], frame.centre[2]);
  const double pixel_angle = 2.0 * kPi / width;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

  base::ParallelFor(0, height, base::ResolveThreads(num_threads), [&](int64_t y64) {
    const int y = static_cast<int>(y64);
    for (int x = 0; x < width; ++x) {
      const Vec3d d = EquirectPixelToDirection(x + 0.5, y + 0.5, width, height);
      const Eigen::Vector3d dir = (pano_to_world * Eigen::Vector3d(d.x, d.y, d.z)).normalized();
      Hit hits[2];
      bool into_ground = false;
      const int found = scene.TraceTwoSurfaces(centre, dir, &hits[0], &hits[1], &into_ground);
      float* px = &out.pixels.at(x, y, 0);
      for (int layer = 0; layer < 2; ++layer) {
        float* v = px + layer * (kBackR - kFrontR);
        if (layer < found) {
          const Eigen::Vector3d c = scene.Shade(hits[layer], centre, dir, pixel_angle);
          const Eigen::Vector3d n = world_to_pano * scene.Normal(hits[layer], centre, dir);
          for (int k = 0; k < 3; ++k) {
            v[kFrontR + k] = static_cast<float>(c[k]);
            v[kFrontNX + k] = static_cast<float>(n[k]);
          }
          v[kFrontZ] = static_cast<float>(hits[layer].t);
        } else if (layer == found && !into_ground) {
          const Eigen::Vector3d c = scene.Sky(dir);
          for (int k = 0; k < 3; ++k) {
            v[kFrontR + k] = static_cast<float>(c[k]);
            v[kFrontNX + k] = 0.0f;
          }
          v[kFrontZ] = kInf;
        } else {
          for (int k = 0; k < 3; ++k) {
            v[kFrontR + k] = 0.0f;
            v[kFrontNX + k] = 0.0f;
          }
          v[kFrontZ] = kNaN;
        }
      }
    }
  });
  return out;
}

}  // namespace casual3d::synth
