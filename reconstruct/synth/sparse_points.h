#pragma once

// The ground-truth COLMAP sparse model of a synthetic capture: the rig's
// camera and poses, and 3D points sampled on visible surfaces. Each photo
// spawns points on a jittered grid of its pixels (sky and the moving object
// excluded); a point's track lists every photo that sees it (inside the image,
// in front of the camera, not occluded in that photo's scene), with the 2D
// observation at its exact projection. Points seen by fewer than `min_track`
// photos are dropped.

#include <cstdint>
#include <string>
#include <vector>

#include "format/status.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/synth/rig.h"
#include "reconstruct/synth/scene.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::synth {

struct SparsePointOptions {
  int step_px = 24;     // Grid spacing of the seed pixels in each photo, pixels, >= 2.
  int min_track = 2;    // Minimum number of observing photos, >= 1.
  uint64_t seed = 1;    // Jitter of the seed pixels.
  int num_threads = 0;  // 0: all cores. Results do not depend on it.

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("step_px", o.step_px, R::Closed(2, 4096), "Grid spacing of the seed pixels in each photo, pixels");
    v.Field("min_track", o.min_track, R::AtLeast(1), "Minimum number of observing photos");
    v.Field("seed", o.seed, R::Any(), "Seed of the seed pixels' jitter");
    v.Field("num_threads", o.num_threads, R::AtLeast(0), "Worker threads; 0 = all cores", util::Keyed::kNo);
  }
  Status Check() const { return util::CheckFields(*this); }  // Names the field and its range.
};

// `scenes[i]` is the scene as photo i saw it (the moving object displaced);
// `names[i]` the image name (e.g. "0000.jpg"). Image ids are i + 1, camera id 1.
geometry::SparseModel MakeGroundTruthModel(const std::vector<Scene>& scenes, const Rig& rig,
                                           const std::vector<std::string>& names,
                                           const SparsePointOptions& options);

}  // namespace casual3d::synth
