#pragma once

// Renders a photo of a Scene through a PINHOLE camera: linear radiance with
// adaptive anti-aliasing (one ray through each pixel centre; pixels whose
// centre hits a different surface than one of their 4 neighbours' -- depth and
// shading edges -- are re-sampled with an n x n grid of rays and averaged),
// the ground-truth depth of the pixel centre, and the development into an 8-bit
// sRGB photo with exposure and sensor noise.

#include <cstdint>
#include <string>

#include "format/status.h"
#include "format/image.h"
#include "reconstruct/geometry/camera.h"
#include "reconstruct/geometry/pose.h"
#include "reconstruct/synth/scene.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::synth {

struct RenderOptions {
  int edge_samples = 3;  // Rays per axis at edge pixels (n x n), 1..8; 1 disables anti-aliasing.
  int num_threads = 0;   // 0: all hardware threads. Results do not depend on it.

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("edge_samples", o.edge_samples, R::Closed(1, 8),
            "Rays per axis at edge pixels (n x n); 1 disables anti-aliasing");
    v.Field("num_threads", o.num_threads, R::AtLeast(0), "Worker threads; 0 = all cores", util::Keyed::kNo);
  }
  Status Check() const { return util::CheckFields(*this); }  // Names the field and its range.
};

struct PhotoRender {
  ImageF radiance;  // Linear RGB, exposure 1.
  // Ground-truth depth of each pixel centre: metres along the optical axis
  // (camera Z), +infinity for sky.
  ImageF depth_m;
  int edge_pixels = 0;  // How many pixels were anti-aliased.
};

// Renders `scene` through `camera` (PINHOLE or SIMPLE_PINHOLE; pixel centres
// at x + 0.5, COLMAP's convention) at `pose` (world to camera).
PhotoRender RenderPhoto(const Scene& scene, const geometry::Camera& camera,
                        const geometry::Pose& pose, const RenderOptions& options);

struct DevelopOptions {
  double exposure = 1.0;     // Multiplies linear radiance (2^stops).
  double noise_sigma = 0.0;  // Gaussian sensor noise, standard deviation in 8-bit code values.
  uint64_t seed = 0;         // Noise seed (per photo).
};

// Linear radiance to 8-bit sRGB: exposure, clamp, sRGB encode, noise, rounding.
Image8 Develop(const ImageF& radiance, const DevelopOptions& options);

}  // namespace casual3d::synth
