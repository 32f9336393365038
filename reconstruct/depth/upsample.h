#pragma once

// Joint bilateral upsampling (Kopf et al. 2007) of a low-resolution depth map
// guided by the full-resolution photo, with a weighted median instead of a
// weighted mean (Ma et al. 2013, Sec. 4.3.1): each output pixel takes one of
// the nearby low-resolution depths, so no mixed depths appear at depth edges.

#include "format/image.h"
#include "format/status.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

struct UpsampleOptions {
  int radius = 2;              // Low-resolution neighbourhood radius, pixels. [1, 8].
  double sigma_spatial = 1.0;  // Gaussian spatial sigma, low-resolution pixels. (0, 16].
  double sigma_color = 0.06;   // Gaussian colour sigma, colour in [0, 1]. (0, 10].
  int num_threads = 0;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("radius", o.radius, R::Closed(1, 8), "Low-resolution neighbourhood radius, pixels");
    v.Field("sigma_spatial", o.sigma_spatial, R::OpenClosed(0, 16), "Spatial sigma, low-resolution pixels");
    v.Field("sigma_color", o.sigma_color, R::OpenClosed(0, 10), "Colour sigma, colour in [0, 1]");
    v.Field("num_threads", o.num_threads, R::AtLeast(0), "Worker threads; 0 = all cores", util::Keyed::kNo);
  }
  Status Check() const { return util::CheckFields(*this); }
};

// `low` is a single-channel map (values <= 0 are invalid and ignored; a pixel
// with no valid neighbour gets 0), `low_color` the RGB guide at low's size and
// `high_color` the RGB guide at the output size. Any single-channel map works
// (depth, confidence).
ImageF JointBilateralMedianUpsample(const ImageF& low, const ImageF& low_color,
                                    const ImageF& high_color, const UpsampleOptions& options);

}  // namespace casual3d::depth
