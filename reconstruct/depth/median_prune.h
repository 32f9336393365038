#pragma once

// The two median pruning filters of the near-envelope anchors (Sec. 4.3.2,
// Fig. 4c-d). A pixel survives when its depth lies within
// [band_low, band_high] times the median of the surviving depths around it,
// or within one depth label of it (far away one label step is wider than the
// band, and a one-label disagreement is quantisation, not an outlier).
//   - MedianPrune: plain median over a small window (5x5 on 900x1350),
//     removes salt-and-pepper noise; pixels with too few valid neighbours
//     (isolated survivors) are removed too.
//   - BilateralMedianPrune: weighted median over a large window (51x51 on
//     900x1350) with colour weights exp(-|c_i - c_j|^2 / (2 sigma_c^2))
//     (Ma et al. 2013), removes large floaters while keeping thin structures
//     whose colour differs from their surroundings.
// Depth maps are in metres with 0 meaning "pruned / invalid".

#include <cmath>

#include "format/image.h"
#include "format/status.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

// The sweep's inverse-depth labels: label k has inverse depth
// inv_near + (inv_far - inv_near) * k / (num_labels - 1).
struct LabelGrid {
  double inv_near = 1.0;  // 1/m.
  double inv_far = 0.0;   // 1/m.
  int num_labels = 2;

  double LabelOf(double depth_m) const {
    return (1.0 / depth_m - inv_near) / (inv_far - inv_near) * (num_labels - 1);
  }
  double DepthOf(double label) const {
    return 1.0 / (inv_near + (inv_far - inv_near) * label / (num_labels - 1));
  }
  double InvStep() const { return std::abs(inv_near - inv_far) / (num_labels - 1); }
};

struct MedianPruneOptions {
  int small_radius = 2;              // Sec. 4.3.2: 5x5 at 900x1350 (scaled by the caller).
  double small_min_valid = 0.2;      // Fraction of the small window that must be valid. [0, 1].
  int large_radius = 25;             // Sec. 4.3.2: 51x51 at 900x1350 (scaled by the caller).
  double sigma_color = 0.033;        // Sec. 4.3.2: sigma_c, colour in [0, 1].
  double band_low = 0.9;             // Sec. 4.3.2: keep if depth / median in [0.9, 1.11].
  double band_high = 1.11;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("small_radius", o.small_radius, R::Closed(1, 64), "Small median radius at 900x1350 (Sec. 4.3.2: 5x5)");
    v.Field("small_min_valid", o.small_min_valid, R::Closed(0, 1), "Fraction of the small window that must be valid");
    v.Field("large_radius", o.large_radius, R::Closed(1, 256), "Bilateral median radius at 900x1350 (Sec. 4.3.2: 51x51)");
    v.Field("sigma_color", o.sigma_color, R::OpenClosed(0, 10), "Bilateral median colour sigma, colour in [0, 1] (Sec. 4.3.2)");
    v.Field("band_low", o.band_low, R::OpenClosed(0, 1), "Keep if depth / median is at least this (Sec. 4.3.2)");
    v.Field("band_high", o.band_high, R::AtLeast(1), "... and at most this");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// Small-window median pruning. Returns the pruned copy of `depth`.
ImageF MedianPrune(const ImageF& depth, const LabelGrid& grid, const MedianPruneOptions& options,
                   int num_threads = 0);

// Colour-weighted large-window median pruning; `color` is RGB in [0, 1] at
// the depth map's size. Returns the pruned copy of `depth`.
ImageF BilateralMedianPrune(const ImageF& depth, const ImageF& color, const LabelGrid& grid,
                            const MedianPruneOptions& options, int num_threads = 0);

}  // namespace casual3d::depth
