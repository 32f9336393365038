#pragma once

// Geometric-consistency (GC) filter of the near-envelope anchors (Sec. 4.3.2,
// after Wolff et al. 2016). Each pixel of a reference WTA depth map is lifted
// to a 3D point and checked against the WTA depth maps of other views:
//   - support: the point's depth in view j agrees with j's depth at its
//     projection within `tolerance_labels` label steps of inverse depth;
//   - visibility violation: the point lies in front of j's surface by more
//     than that (j would have seen it, but saw something farther);
//   - otherwise (behind j's surface, or outside j) j says nothing.
// A pixel is kept when support >= min_support and
// violations <= max_violation_ratio * support. Comparing in inverse depth
// with a tolerance in label steps matches the WTA maps' own quantisation.

#include <vector>

#include "format/image.h"
#include "format/status.h"
#include "reconstruct/depth/view.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

struct GcFilterOptions {
  double tolerance_labels = 2.0;     // Agreement band, label steps of inverse depth. [0.5, 50].
  int min_support = 2;               // Views that must agree. [1, 64].
  double max_violation_ratio = 1.0;  // Allowed violations per supporting view. [0, 64].
  int max_views = 8;                 // Other views checked (best neighbours first). [1, 256].

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("tolerance_labels", o.tolerance_labels, R::Closed(0.5, 50), "Agreement band, label steps of inverse depth");
    v.Field("min_support", o.min_support, R::Closed(1, 64), "Views that must agree");
    v.Field("max_violation_ratio", o.max_violation_ratio, R::Closed(0, 64), "Allowed violations per supporting view");
    v.Field("max_views", o.max_views, R::Closed(1, 256), "Other views checked (best neighbours first)");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// `depth_maps[i]` is view i's WTA depth (metres, 0 = invalid) at the size of
// views[i].camera. `others` lists the views to check against (indices into
// views, excluding `ref`), best first; at most max_views are used.
// `inv_step` is the inverse-depth step between labels of the reference (1/m).
// Returns the reference map with inconsistent pixels set to 0.
ImageF GeometricConsistencyFilter(int ref, const std::vector<const DenseView*>& views,
                                  const std::vector<const ImageF*>& depth_maps,
                                  const std::vector<int>& others, double inv_step,
                                  const GcFilterOptions& options, int num_threads = 0);

}  // namespace casual3d::depth
