#pragma once

// The view hints of a 3D photo (format/view_hints.h) from its capture: where
// the viewer opens, the captured content's angular extent, and the viewing
// volume the capture supports (spec/package.md Sec. 3.1; spec/stage-panorama.md,
// "View hints").
//
//   direction  the mean of the photos' optical axes in the panorama frame,
//              moved inside the content's extent.
//   fov        the photos' median short-side field of view, narrowed so that
//              a 16:9 view at that direction stays inside the content.
//   content    the longitudes and latitudes of the field-of-view mask's
//              pixels; the longitudes are the circle minus its largest run of
//              empty columns (render::YawExtentOfColumns, so content across
//              +-180 degrees stays one interval).
//   volume     a ball around the centre whose radius is the largest distance
//              of a camera centre from it, kept within
//              [min_radius_over_near, max_radius_over_near] times the near
//              depth (a low percentile of the front depths in the field of
//              view): a head moved by r opens a gap of up to r / near
//              radians beside a near object, which the back layer's growth
//              (fuse expansion_fraction) must fill; the panorama stage
//              lowers the bound to what that growth covers.

#include <vector>

#include "format/image.h"
#include "format/two_layer.h"
#include "format/view_hints.h"
#include "reconstruct/pipeline/coverage.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::pipeline {

struct ViewVolumeOptions {
  // Percentile of the front depths inside the field of view taken as the
  // near depth; [0, 0.5].
  double near_percentile = 0.05;
  // Bounds of the volume's radius, as fractions of the near depth;
  // 0 < min <= max <= 1.
  double min_radius_over_near = 0.02;
  double max_radius_over_near = 0.06;
  // Aspect ratio (width / height) of the view the opening field of view must
  // fit; [0.25, 4].
  double frame_aspect = 16.0 / 9.0;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("near_percentile", o.near_percentile, R::Closed(0, 0.5), "Percentile of the front depths taken as the near depth");
    v.Field("min_radius_over_near", o.min_radius_over_near, R::OpenClosed(0, 1), "Smallest volume radius, fraction of the near depth");
    v.Field("max_radius_over_near", o.max_radius_over_near, R::OpenClosed(0, 1), "Largest volume radius, fraction of the near depth");
    v.Field("frame_aspect", o.frame_aspect, R::Closed(0.25, 4), "Aspect ratio of the view the opening field of view fits");
    v.Require(o.min_radius_over_near <= o.max_radius_over_near, "min_radius_over_near", "must not exceed max_radius_over_near");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// Content extent of a field-of-view mask (width x height x 1, non-zero
// inside): sets the content_* members of `hints`; false, leaving them, when
// the mask is empty. When more than 0.5% of the box of the mask's
// longitudes and latitudes is empty, the box becomes FitContentBox's.
bool ContentExtent(const Image8& fov_mask, ViewHints* hints);

// Replaces the content box of `hints` (unless it goes all around) by the box
// inside it, on a grid of cells of about 1/256 of the circle, that holds the
// most content (solid angle inside `fov_mask`) with at most
// `max_empty_fraction` of its solid angle outside: the corners of a capture
// that is not a rectangle (sky above trees that no photo saw) leave the box,
// so that a view kept inside it shows content. Unchanged when no box fits.
void FitContentBox(const Image8& fov_mask, double max_empty_fraction, ViewHints* hints);

// The hints for panorama `pano` whose photos are `views` (world poses) in
// `frame`; `fov_mask` is the photos' field of view (coverage.h) at the
// panorama's size. `metric`: whether the frame's unit is the metre.
ViewHints ComputeViewHints(const TwoLayerPanorama& pano, const Image8& fov_mask,
                           const std::vector<CoverageView>& views, const PanoramaFrame& frame,
                           bool metric, const ViewVolumeOptions& options = ViewVolumeOptions());

}  // namespace casual3d::pipeline
