#pragma once

// Edge-aware weighted median of an MRF labelling (Ma et al. 2013, the filter
// the paper already uses for upsampling in Sec. 4.3.1, here at the working
// resolution and with a wider window).
//
// Window-based photo-consistency (ZNCC over a (2r+1)^2 window) fattens near
// objects: background pixels within a window radius of a near object's edge
// match at the near object's depth (the edge dominates their window), which
// leaves a band of near floaters around poles, spheres and tree crowns. Each
// pixel here takes the weighted median label of its window, the weights being
// a spatial Gaussian times a colour affinity to the centre pixel. Background
// pixels of a fattened band then take the label of the background pixels of
// their own colour farther out, while the depth edge snaps to the colour edge.
// The weights deliberately ignore the sweep's texture confidence: pixels of a
// fattened band have a textured window (the edge), so weighting by it would
// favour exactly the pixels this filter corrects.

#include <vector>

#include "format/image.h"
#include "format/status.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

struct EdgeMedianOptions {
  // Fattening reaches one ZNCC window radius (3) into the background; the
  // median restores a band of width b when the window holds more correct
  // background pixels than band pixels, i.e. radius > 2 b (flat weights).
  int radius = 8;              // Window radius, working pixels; 0 = off. [0, 32].
  double sigma_spatial = 8.0;  // Spatial Gaussian sigma, working pixels. (0, 64].
  double sigma_color = 0.05;   // Colour affinity sigma, colour in [0, 1]. (0, 10].

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("radius", o.radius, R::Closed(0, 32), "Edge-aware median window radius, working pixels; 0 = off");
    v.Field("sigma_spatial", o.sigma_spatial, R::OpenClosed(0, 64), "Edge-aware median spatial sigma, working pixels");
    v.Field("sigma_color", o.sigma_color, R::OpenClosed(0, 10), "Edge-aware median colour sigma, colour in [0, 1]");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// `labels` (width * height, row-major, values in [0, num_labels)) and `color`
// the RGB guide in [0, 1] of the same size. Returns the filtered labels.
std::vector<int> EdgeAwareMedian(const std::vector<int>& labels, int num_labels,
                                 const ImageF& color, const EdgeMedianOptions& options,
                                 int num_threads = 0);

}  // namespace casual3d::depth
