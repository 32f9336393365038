#pragma once

// Normal maps for lighting effects (paper Sec. 5, Fig. 11): plausible rather
// than exact normals, computed on the fused two-layer graph.
//   1. Base normals: central differences of the nodes' 3D positions along
//      links only (one-sided where a link is missing), then smoothed by the
//      linear system of Eq. 5 with data constraints everywhere and binary
//      smoothness weights (1 across a link, 0 across a depth discontinuity),
//      solved by Jacobi iterations.
//   2. Detail normals hallucinated from luminance (Khan et al. 2006: brighter
//      is nearer): the high-pass luminance is a height field whose gradient
//      tilts a normal facing the centre.
//   3. The detail is transferred onto the base normal through the local
//      frames of Eq. 14 to 16: n_c = R_f^-1 R_s n_i.
//   4. Sky detection: far, smooth, bright-or-bluish front nodes connected to
//      the top of the panorama get a zero normal (unlit).
// spec/stage-panorama.md documents the same choices.

#include <string>

#include "format/two_layer.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::normals {

struct NormalOptions {
  // Eq. 5 with binary weights: smoothness weight relative to the data weight; > 0.
  double smoothness = 8.0;
  // Jacobi iterations of the smoothing system; >= 0.
  int iterations = 48;
  // Strength of the hallucinated detail: tilt per unit of high-pass luminance
  // difference between neighbours (luminance in [0, 1]); >= 0 (0 disables).
  double detail_strength = 4.0;
  // Radius of the low-pass that separates detail from shading, pixels; >= 1.
  int detail_radius = 3;
  // Sky: node depth at or beyond this fraction of the 99th-percentile depth...
  double sky_depth_fraction = 0.9;
  // ...with luminance standard deviation over its 3x3 linked neighbourhood below this.
  double sky_max_texture = 0.03;
  bool detect_sky = true;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("smoothness", o.smoothness, R::Above(0), "Smoothness weight relative to the data weight (Eq. 5)");
    v.Field("iterations", o.iterations, R::Closed(0, 10000), "Jacobi iterations of the smoothing system");
    v.Field("detail_strength", o.detail_strength, R::AtLeast(0), "Strength of the hallucinated detail; 0 disables");
    v.Field("detail_radius", o.detail_radius, R::Closed(1, 64), "Radius of the low-pass that separates detail, pixels");
    v.Field("sky_depth_fraction", o.sky_depth_fraction, R::OpenClosed(0, 1), "Sky: depth from this fraction of the 99th percentile");
    v.Field("sky_max_texture", o.sky_max_texture, R::AtLeast(0), "Sky: luminance deviation below this");
    v.Field("detect_sky", o.detect_sky, R::Any(), "Find sky nodes and give them a zero normal (unlit)");
  }
  Status Check() const { return util::CheckFields(*this); }
};

struct NormalStats {
  long nodes = 0;
  long sky_nodes = 0;
};

// Fills the normals of every present node of `pano` (unit length, pointing
// towards the centre's side of the surface, or zero for sky). Throws
// std::invalid_argument on invalid options.
NormalStats ComputeNormals(TwoLayerPanorama* pano, const NormalOptions& options);

}  // namespace casual3d::normals
