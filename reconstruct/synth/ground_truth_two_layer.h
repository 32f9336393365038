#pragma once

// Turns a ground-truth panorama (first and second surfaces, see
// ground_truth_panorama.h) into the paper's two-layer panorama
// (format/two_layer.h), so that a synthetic capture comes with a reference 3D
// photo:
//   - front nodes everywhere (label F), back nodes (label B) where a second
//     surface exists, except where it is too close to the front one: dropped
//     when depth(front) / depth(back) > tau_dratio (Sec. 4.4.3, tau_dratio = 0.75);
//   - colour: the linear radiance encoded as 8-bit sRGB;
//   - depth: the distance along the ray; the sky (+inf) is clamped to a finite
//     far depth (`sky_depth_m`, raised to twice the farthest finite depth if
//     that is farther) and gets the normal (0, 0, 0) (unlit);
//   - links: for each pair of 4-neighbouring pixels, node pairs are considered
//     most similar depth first and linked when min(d)/max(d) > `link_ratio`,
//     each node taking at most one link per direction and links never crossing
//     (a front-to-back link and a back-to-front one between the same pixels);
//     links are mutual; right/left wrap around the 180 degree seam.

#include "format/status.h"
#include "format/two_layer.h"
#include "reconstruct/synth/ground_truth_panorama.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::synth {

struct TwoLayerOptions {
  double tau_dratio = 0.75;   // Sec. 4.4.3: back nodes with d(f)/d(b) above this are dropped, (0, 1].
  double link_ratio = 0.9;    // Neighbours link when their depth ratio is above this, (0, 1).
  double sky_depth_m = 1000.0;  // Depth given to the sky, metres, > 0.

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("tau_dratio", o.tau_dratio, R::OpenClosed(0, 1),
            "Sec. 4.4.3: back nodes with d(f)/d(b) above this are dropped");
    v.Field("link_ratio", o.link_ratio, R::Open(0, 1),
            "Neighbours link when their depth ratio is above this");
    v.Field("sky_depth_m", o.sky_depth_m, R::Above(0), "Depth given to the sky, metres");
  }
  Status Check() const { return util::CheckFields(*this); }  // Names the field and its range.
};

// Precondition: options.Check() is ok and the panorama has kNumPanoramaChannels channels.
TwoLayerPanorama GroundTruthToTwoLayer(const GroundTruthPanorama& gt, const TwoLayerOptions& options);

}  // namespace casual3d::synth
