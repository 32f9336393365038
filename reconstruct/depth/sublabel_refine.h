#pragma once

// Sub-label depth refinement after the MRF (Sec. 4.3.1 solves on 220 discrete
// inverse-depth labels; far content spans only a few labels, so rounding to a
// label alone costs several percent of depth there).
//
// Two steps on fractional labels (label space is linear in inverse depth):
//  1. Per pixel, a parabola through E_photo at the best of the labels k-1, k,
//     k+1 around the MRF label k, when that label is a local minimum of the
//     cost (the classic sub-sample peak fit of stereo matching). The result is
//     kept within [k - 1, k + 1].
//  2. An edge-aware weighted mean of the fractional labels over a small
//     window: neighbours count with a colour affinity times their texture
//     confidence (w_photo), and only when their label lies within
//     `max_label_gap` of the centre's, so depth edges are never blurred. On
//     slanted or curved surfaces this turns the staircase of discrete labels
//     (and the parabola fit's bias towards integer labels) into a smooth
//     surface; on a plane the mean of a symmetric window is unbiased.

#include <vector>

#include "format/image.h"
#include "format/status.h"
#include "reconstruct/depth/plane_sweep.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

struct SubLabelOptions {
  bool parabola = true;            // Step 1. Off: start from the integer labels.
  int smooth_radius = 2;           // Step 2 window radius, working pixels; 0 = off. [0, 8].
  int smooth_iterations = 2;       // Step 2 passes. [0, 16].
  double sigma_color = 0.05;       // Colour affinity sigma, colour in [0, 1]. (0, 10].
  double max_label_gap = 1.5;      // Neighbours farther than this (labels) are ignored. (0, 16].
  double confidence_floor = 0.05;  // Added to w_photo so textureless areas still average. (0, 1].

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("parabola", o.parabola, R::Any(), "Step 1: parabola fit around each label");
    v.Field("smooth_radius", o.smooth_radius, R::Closed(0, 8), "Step 2 window radius, working pixels; 0 = off");
    v.Field("smooth_iterations", o.smooth_iterations, R::Closed(0, 16), "Step 2 passes");
    v.Field("sigma_color", o.sigma_color, R::OpenClosed(0, 10), "Colour affinity sigma, colour in [0, 1]");
    v.Field("max_label_gap", o.max_label_gap, R::OpenClosed(0, 16), "Neighbours farther than this (labels) are ignored");
    v.Field("confidence_floor", o.confidence_floor, R::OpenClosed(0, 1), "Added to w_photo so textureless areas still average");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// `volume` holds E_photo and w_photo, `labels` the MRF labels (width * height,
// row-major), `color` the working-resolution RGB guide in [0, 1]. Returns the
// fractional labels (row-major); convert with CostVolume::DepthOfLabel.
std::vector<float> RefineSubLabel(const CostVolume& volume, const std::vector<int>& labels,
                                  const ImageF& color, const SubLabelOptions& options,
                                  int num_threads = 0);

// The two steps on their own (the dense stage times them apart):
// RefineSubLabel(...) equals
// SmoothSubLabel(volume, FitSubLabel(volume, labels, ...), color, ...).
std::vector<float> FitSubLabel(const CostVolume& volume, const std::vector<int>& labels,
                               const SubLabelOptions& options, int num_threads = 0);
std::vector<float> SmoothSubLabel(const CostVolume& volume, std::vector<float> labels,
                                  const ImageF& color, const SubLabelOptions& options,
                                  int num_threads = 0);

}  // namespace casual3d::depth
