#pragma once

// Smoothing of a stitched layer's depth along its surfaces.
//
// Each pass replaces every pixel's log-depth by the mean log-depth of the
// pixels in the (2 radius + 1)^2 window around it (columns wrap at +-180
// degrees) whose depth lies within `tolerance` (relative) of its own, itself
// included. Depth steps larger than the tolerance are left as they are, and a
// plane keeps its place (a symmetric mean of a linear function), so what goes
// is the pixel-scale noise of the depth maps: the mesh's small bumps, and the
// bits a lossless coder would spend on them. spec/stage-panorama.md, "Depth
// smoothing".

#include "format/image.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::stitch {

struct DepthSmoothOptions {
  int radius = 2;            // Window half-size, pixels; 0 disables. [0, 8].
  int iterations = 2;        // Passes. [1, 16].
  double tolerance = 0.03;   // Relative depth within which pixels average; (0, 1).

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("radius", o.radius, R::Closed(0, 8), "Depth smoothing window half-size, pixels; 0 disables");
    v.Field("iterations", o.iterations, R::Closed(1, 16), "Depth smoothing passes");
    v.Field("tolerance", o.tolerance, R::Open(0, 1), "Relative depth within which pixels are averaged");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// Smooths `depth_m` in place (0 or non-finite = no depth; left as is).
// Throws std::invalid_argument on invalid options.
void SmoothDepthAlongSurfaces(ImageF* depth_m, const DepthSmoothOptions& options,
                              int num_threads = 0);

}  // namespace casual3d::stitch
