#pragma once

// Free-space check of the final depth maps against each other (ours; the
// paper leaves such outliers to the stitcher's data term).
//
// Once every photo has its final depth map, a point of photo i's map that
// other photos see through is not there: projected into view j, it lies in
// front of j's surface by more than a tolerance, so j's ray passed through it
// to reach something farther. What is left after the
// envelope and the MRF is mostly of this kind: background in narrow
// textureless gaps beside near objects, and blank strips at the image border,
// which took a near object's depth where the reference photo alone cannot
// tell (docs/DECISIONS.md, "Dense: free-space check"). The other photos saw those
// surfaces from elsewhere, often where they carry texture or a prior.
//
// A pixel is flagged when at least `min_violations` views see through it and
// more views see through it than agree with it (within the tolerance). A view
// sees through a point only if even the nearest depth of its 3x3 pixels
// around the projection lies beyond it, so that a depth edge a pixel off does
// not count. A flagged pixel takes the lower median, over the views, of what
// each renders along its ray beyond the flagged depth (its depth map splatted
// into the reference with a z-buffer): the nearer of two middle candidates, so
// that the result is one of the surfaces and not a depth between two. Where
// no view renders anything there, the pixel keeps its depth. The check only
// ever moves a depth farther.
//
// The other maps have errors of their own: a thin object that a neighbour's
// map lost is seen through there. So a flagged pixel moves only when the
// photos agree at least as well with the farther depth: the grey levels a
// 5x5 window around the pixel (every second pixel) projects onto in each
// view at that depth,
// against the window's own (mean absolute difference), averaged over the
// better half of the views (the others may see an occluder), may not exceed
// the same at the current depth by more than photo_margin (how many wrong
// and right moves it keeps: docs/DECISIONS.md, "Dense: free-space check").

#include <vector>

#include "format/image.h"
#include "format/status.h"
#include "reconstruct/depth/view.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

struct VisibilityFilterOptions {
  bool enabled = true;
  // Band of agreement in inverse depth around a depth z: the larger of
  // tolerance / z (relative) and tolerance_labels label steps; 0 labels =
  // no floor (docs/DECISIONS.md, "Dense: free-space check"). (0, 1], [0, 100].
  double tolerance = 0.03;
  double tolerance_labels = 0.0;
  int min_violations = 2;      // Views that must see through a point. [1, 255].
  int max_views = 12;          // Other views checked (best neighbours first). [1, 255].
  int rounds = 1;              // Check-and-replace rounds over all photos. [1, 10].
  bool photo_gate = true;      // Move only where the photos agree (above).
  double photo_margin = 0.02;  // Grey levels in [0, 1]. [0, 1].
  int photo_radius = 2;        // The compared window's half-size, pixels. [0, 10].
  int photo_stride = 2;        // ... sampled every this many pixels. [1, 10].

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("enabled", o.enabled, R::Any(), "Free-space check of the depth maps against each other");
    v.Field("tolerance", o.tolerance, R::OpenClosed(0, 1),
            "Relative depth band within which another photo's depth agrees (free-space check)");
    v.Field("tolerance_labels", o.tolerance_labels, R::Closed(0, 100),
            "... or this many label steps of inverse depth, whichever is larger");
    v.Field("min_violations", o.min_violations, R::Closed(1, 255), "Views that must see through a point");
    v.Field("max_views", o.max_views, R::Closed(1, 255), "Other photos each depth map is checked against (best neighbours first)");
    v.Field("rounds", o.rounds, R::Closed(1, 10), "Rounds of the free-space check over all photos");
    v.Field("photo_gate", o.photo_gate, R::Any(), "Move only where the photos agree");
    v.Field("photo_margin", o.photo_margin, R::Closed(0, 1), "Photo agreement margin, grey levels in [0, 1]");
    v.Field("photo_radius", o.photo_radius, R::Closed(0, 10), "The compared window's half-size, pixels");
    v.Field("photo_stride", o.photo_stride, R::Closed(1, 10), "The compared window's sample spacing, pixels");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// One replaced pixel of a depth map.
struct DepthReplacement {
  int index = 0;       // y * width + x.
  float depth = 0.0f;  // Metres.
};

struct VisibilityStats {
  long long flagged = 0;   // Pixels that other views see through.
  long long replaced = 0;  // ... of which got a farther depth.
};

// `cameras[k]`, `depths[k]` (metres; non-finite or <= 0 = no depth) and
// `grays[k]` (1 channel, in [0, 1]) are view k's, all at the same size.
// Checks view `ref` against `others` (indices,
// best first; `ref` itself skipped; at most options.max_views used) and
// returns the replacements, in increasing index order. Reads the maps only.
// `inv_step` is the reference's label step of inverse depth (1/m).
std::vector<DepthReplacement> CheckFreeSpace(int ref,
                                             const std::vector<const PinholeCamera*>& cameras,
                                             const std::vector<const ImageF*>& depths,
                                             const std::vector<const ImageF*>& grays,
                                             const std::vector<int>& others, double inv_step,
                                             const VisibilityFilterOptions& options,
                                             VisibilityStats* stats = nullptr);

}  // namespace casual3d::depth
