#pragma once

// Accuracy of depth maps against ground truth (metres along the optical
// axis, +inf or non-finite for sky), as the dense stage reports them
// (spec/stage-dense.md, "Evaluation"). Maps may differ in size: the ground
// truth is sampled at each estimate pixel's centre (nearest pixel).

#include <cstdint>
#include <vector>

#include "format/image.h"
#include "reconstruct/depth/view.h"

namespace casual3d::depth {

// Final depth map accuracy over pixels with finite ground truth.
struct DepthAccuracy {
  long long pixels = 0;            // Pixels with finite ground truth.
  double median_rel_error = 0.0;   // median |d - g| / g.
  double within_3pct = 0.0;        // Fraction with |d - g| / g <= 0.03.
  double near_floaters = 0.0;      // Fraction with d < 0.85 g (or d missing).
  // Error in label steps (|1/d - 1/g| / inv_step), when inv_step > 0 is given:
  // tells quantisation (well under a label) from gross errors.
  double within_half_label = 0.0;  // Fraction with |1/d - 1/g| <= 0.5 inv_step.
  double within_two_labels = 0.0;  // Fraction with |1/d - 1/g| <= 2 inv_step.
  long long sky_pixels = 0;        // Pixels with infinite ground truth.
  double sky_near = 0.0;           // Fraction of sky pixels with d < sky_near_m.
  // With observer counts: the same figures over the pixels whose true
  // surface at least min_observers of the swept neighbours see, the only ones
  // photo-consistency can say anything about.
  long long observed_pixels = 0;
  double median_rel_error_observed = 0.0;
  double within_3pct_observed = 0.0;
  double near_floaters_observed = 0.0;
};
// `sky_near_m`: depth below which an estimate on a sky pixel counts as a
// near floater (callers pass half the sweep's far bound). `inv_step`: the
// sweep's inverse-depth label spacing (1/m), 0 = no label statistics.
// `observers` (optional): AgreeingViews of the ground truth, at its size.
DepthAccuracy EvaluateDepth(const ImageF& depth, const ImageF& ground_truth, double sky_near_m,
                            double inv_step = 0.0, const std::vector<uint8_t>* observers = nullptr,
                            int min_observers = 2);

// Completeness and precision of a pruned anchor map (Fig. 6, left).
// An anchor is an inlier when |1/d - 1/g| <= inv_tolerance (1/m), which also
// handles sky (1/g = 0).
struct AnchorQuality {
  double completeness = 0.0;  // Fraction of all pixels that are anchors.
  double precision = 0.0;     // Fraction of anchors that are inliers.
};
AnchorQuality EvaluateAnchors(const ImageF& anchors, const ImageF& ground_truth, double inv_tolerance);

// Near envelope quality (Fig. 6, right).
struct EnvelopeQuality {
  double error = 0.0;      // Fraction of pixels where the envelope lies behind the true surface.
  double tightness = 0.0;  // Mean of 1/n - 1/g over pixels with finite ground truth, 1/m.
};
EnvelopeQuality EvaluateEnvelope(const ImageF& envelope, const ImageF& ground_truth);

// Per pixel of `ref_depth` (a depth map of `ref_camera`, at its size), how many
// of the other maps agree with it within `rel_tolerance`: the pixel's 3D point
// lies in front of camera k, projects inside depths[k] (a map of cameras[k],
// at its size), and |z_k - d_k| <= rel_tolerance d_k there. kNoDepth where
// the pixel has no valid depth. With ground-truth maps it counts the views
// that see the pixel's surface (inside the frame, not occluded). Only the
// first 254 cameras are used, so that a count never reaches kNoDepth.
constexpr uint8_t kNoDepth = 255;
std::vector<uint8_t> AgreeingViews(const PinholeCamera& ref_camera, const ImageF& ref_depth,
                                   const std::vector<const PinholeCamera*>& cameras,
                                   const std::vector<const ImageF*>& depths, double rel_tolerance);

// Cross-view consistency, which needs no ground truth: the
// fraction of view `ref`'s pixels with a valid depth whose 3D point, projected
// into the other views listed in `others` (indices into `views`, at most
// `max_views` used), agrees within `rel_tolerance` (|z_j - d_j| / d_j, z_j the
// point's depth in view j, d_j view j's depth at the projection) with at least
// `min_views` of them. `depths[i]` is view i's depth map (metres, <= 0 or
// non-finite = none) at the size of views[i]->camera. Returns 0 when view
// `ref` has no valid depth.
double CrossViewConsistency(int ref, const std::vector<const DenseView*>& views,
                            const std::vector<const ImageF*>& depths, const std::vector<int>& others,
                            double rel_tolerance = 0.02, int min_views = 2, int max_views = 8);

}  // namespace casual3d::depth
