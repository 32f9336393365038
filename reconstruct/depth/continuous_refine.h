#pragma once

// Continuous depth refinement around the MRF's labels (ours; the paper stops
// at its 220 discrete labels). The labels are spaced uniformly in inverse
// depth, so one label step is a fixed disparity step: at this stage's working
// resolution and a casual capture's baselines it is one to two pixels of
// disparity, coarser than a ZNCC window can resolve. Far content spans only a
// few labels, so rounding to a label costs 10-40% of depth there, and a
// parabola through costs sampled that coarsely has errors of a quarter label.
//
// Per textured pixel (w_photo >= min_weight), this re-evaluates the sweep's
// photo-consistency directly at continuous inverse depths near the chosen
// label k: the same ZNCC over the same window, the fronto-parallel plane's
// homography per window pixel and bilinear sampling, aggregated over the
// pixel's best `best_k` neighbours (picked once at label k). It searches
// offsets in [-search_labels, +search_labels] on a grid of `coarse_step`
// labels, then halves the step around the best offset and fits a parabola.
// The result stays within search_labels of k, so the MRF's decision (which
// surface) is never overturned, only located more precisely. Where the
// search finds nothing better than the starting value, that value is kept.
//
// Cost: per refined pixel about 2 * search_labels / coarse_step + 2
// evaluations for best_k neighbours plus one per neighbour at k, each a
// (2r+1)^2 window; linear in pixels x evaluations x window.

#include <vector>

#include "format/image.h"
#include "format/status.h"
#include "reconstruct/depth/plane_sweep.h"
#include "reconstruct/depth/view.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

struct ContinuousRefineOptions {
  // Off by default: the search costs a ZNCC evaluation per step and
  // neighbour at every pixel (docs/DECISIONS.md, "Dense: continuous search
  // around each label").
  bool enabled = false;
  double search_labels = 1.0;  // Half-width of the search around the MRF label. (0, 4].
  double coarse_step = 0.25;   // Grid step of the first search, labels. (0, search_labels].
  double min_weight = 0.1;     // Pixels with lower w_photo keep their value. [0, 1].

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("enabled", o.enabled, R::Any(), "Continuous depth search around each MRF label");
    v.Field("search_labels", o.search_labels, R::OpenClosed(0, 4), "Half-width of the search around the MRF label, labels");
    v.Field("coarse_step", o.coarse_step, R::Above(0), "Grid step of the first search, labels");
    v.Field("min_weight", o.min_weight, R::Closed(0, 1), "Pixels with a lower w_photo keep their value");
    v.Require(o.coarse_step <= o.search_labels, "coarse_step", "must not exceed search_labels");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// `start` holds per pixel the fractional label to refine (for example
// FitSubLabel's output) and `labels` the MRF's integer labels, both row-major
// at the reference view's working size; `volume` gives the label grid
// (inv_near, inv_far, num_labels) and w_photo (its costs are not read).
// `sweep` supplies the window radius, ncc_epsilon and best_k of the sweep.
// Returns the refined fractional labels. Throws std::invalid_argument on bad
// options or sizes.
std::vector<float> RefineContinuous(const DenseView& ref, const std::vector<const DenseView*>& neighbors,
                                    const CostVolume& volume, const std::vector<int>& labels,
                                    const std::vector<float>& start, const SweepOptions& sweep,
                                    const ContinuousRefineOptions& options, int num_threads = 0);

}  // namespace casual3d::depth
