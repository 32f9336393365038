#pragma once

// Depth of textureless regions from their silhouettes (ours; the paper's
// near envelope only keeps such regions from floating, and leaves their depth
// to the MRF, which has no evidence there).
//
// A flat region (a blank wall, a painted panel) carries no photo-consistency
// inside: ZNCC of a uniform window is noise. What the photos do say is where
// its boundary is in every view, and a boundary point's depth bounds the
// region's:
//   - where the region occludes what lies beyond (its silhouette), or stands
//     on it (a wall on the ground: a contact), the region is at the edge's depth;
//   - where something in front occludes it (a pole across a wall), the edge
//     is at the occluder's depth, nearer than the region.
// So along its boundary the region is never nearer than its edges, and it
// touches the farthest of them. This module:
//   1. segments the flat pixels (w_photo below max_photo_weight) into regions
//      of nearly constant colour, and joins regions of the same colour that
//      a thin occluder separates (the strips of a wall between poles);
//   2. locates each boundary point's colour edge to a fraction of a pixel
//      and measures its depth from the colours alone: for each label, the
//      point and its outward normal are projected into each neighbour,
//      whose colour profile across the projected edge (times the pair's
//      exposure gain) is compared with the reference's. A ZNCC window over
//      the edge would be dominated by the texture beyond and match there;
//   3. classifies each edge by the surface just beyond it (from the
//      winner-takes-all depths): farther (the region's silhouette), the
//      region itself again (a thin occluder crossing it) or at the edge's
//      depth (an occluder's edge, or a contact with the ground);
//   4. fits per group a plane in label space (labels are affine in pixel
//      coordinates for a plane) that lies behind all but a few edge points
//      and touches as many as possible, on silhouette points, on points
//      that enclose the region, or on its contact with the surface below;
//      a group without its own fit adopts a close same-coloured group's
//      plane when its edges agree. Sky-like regions get none.
// The result is a prior label per pixel of every fitted group, for the MRF's
// data term and the sub-label step (dense_stage.cc).

#include <vector>

#include "format/image.h"
#include "format/status.h"
#include "reconstruct/depth/plane_sweep.h"
#include "reconstruct/depth/view.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

struct FlatRegionOptions {
  bool enabled = true;
  double max_photo_weight = 0.1;  // Flat pixels: w_photo below this. [0, 1].
  double color_step = 0.03;       // Region growing: RGB distance between 4-neighbours. (0, 1].
  double color_spread = 0.08;     // ... and to the region's mean colour. (0, 1].
  double min_area_fraction = 0.002;  // A group's pixels / the image's. [0, 1].
  // A fitted plane also covers connected pixels of the group's colour (within
  // color_spread) whose w_photo is below this. [0, 1].
  double extend_max_photo_weight = 0.5;
  int min_region_pixels = 30;     // Smaller regions are not segmented. [1, 1e6].
  int merge_gap = 12;             // Regions this close (pixels) with similar colour join. [0, 256].
  double merge_color = 0.05;      // ... similar: RGB distance of the means. [0, 1].
  double edge_contrast = 0.1;     // A boundary point's outside must differ this much (RGB L1). [0, 3].
  double edge_tau = 0.12;         // Colour difference (RGB L1) that counts fully in the edge test. (0, 3].
  int max_edge_points = 1500;     // Boundary points tested per group (evenly subsampled). [10, 1e6].
  double touch_labels = 1.0;      // A point touches the plane within this many labels. (0, 100].
  double behind_fraction = 0.9;   // The plane lies behind at least this fraction of the points. [0, 1].
  int min_touching = 25;          // Touching points a fit needs (owned ones count twice). [3, 1e6].
  int min_owned = 10;             // ... of which owned (silhouette) points. [1, 1e6].
  double owned_margin = 1.5;      // The surface beyond a silhouette is this many labels farther. [0, 1000].
  double min_touching_fraction = 0.05;  // ... and this fraction of the group's points. [0, 1].
  int min_side_points = 5;        // Touching points on a side that counts as holding the region. [1, 1e6].
  int adopt_distance = 48;        // Pixels between the boxes of groups that share a plane. [0, 1e6].

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("enabled", o.enabled, R::Any(), "Depth priors for textureless regions from their silhouettes");
    v.Field("max_photo_weight", o.max_photo_weight, R::Closed(0, 1), "Flat pixels have a w_photo below this");
    v.Field("color_step", o.color_step, R::OpenClosed(0, 1), "Region growing: RGB distance between 4-neighbours");
    v.Field("color_spread", o.color_spread, R::OpenClosed(0, 1), "Region growing: RGB distance to the region's mean");
    v.Field("min_area_fraction", o.min_area_fraction, R::Closed(0, 1), "Smallest group, fraction of the image's pixels");
    v.Field("extend_max_photo_weight", o.extend_max_photo_weight, R::Closed(0, 1),
            "A fitted plane also covers connected pixels of its colour with w_photo below this");
    v.Field("min_region_pixels", o.min_region_pixels, R::Closed(1, 1e6), "Smaller regions are not segmented, pixels");
    v.Field("merge_gap", o.merge_gap, R::Closed(0, 256), "Regions this close (pixels) with similar colour join");
    v.Field("merge_color", o.merge_color, R::Closed(0, 1), "Similar colour for merging: RGB distance of the means");
    v.Field("edge_contrast", o.edge_contrast, R::Closed(0, 3), "A boundary point's outside differs this much (RGB L1)");
    v.Field("edge_tau", o.edge_tau, R::OpenClosed(0, 3), "Colour difference (RGB L1) counting fully in the edge test");
    v.Field("max_edge_points", o.max_edge_points, R::Closed(10, 1e6), "Boundary points tested per group");
    v.Field("touch_labels", o.touch_labels, R::OpenClosed(0, 100), "A point touches the plane within this many labels");
    v.Field("behind_fraction", o.behind_fraction, R::Closed(0, 1), "The plane lies behind at least this fraction of the points");
    v.Field("min_touching", o.min_touching, R::Closed(3, 1e6), "Touching points a fit needs (owned ones count twice)");
    v.Field("min_owned", o.min_owned, R::Closed(1, 1e6), "Owned (silhouette) points among them");
    v.Field("owned_margin", o.owned_margin, R::Closed(0, 1000), "The surface beyond a silhouette is this many labels farther");
    v.Field("min_touching_fraction", o.min_touching_fraction, R::Closed(0, 1), "Touching points, fraction of the group's points");
    v.Field("min_side_points", o.min_side_points, R::Closed(1, 1e6), "Touching points on a side that holds the region");
    v.Field("adopt_distance", o.adopt_distance, R::Closed(0, 1e6), "Pixels between the boxes of groups that share a plane");
  }
  Status Check() const { return util::CheckFields(*this); }
};

struct FlatRegionStats {
  int groups = 0;        // Groups of at least min_area_fraction.
  int fitted = 0;        // Groups with a plane.
  long long pixels = 0;  // Pixels with a prior.
  int edge_points = 0;   // Boundary points with a confident edge depth.
};

// A neighbour's working-resolution colour image and camera.
struct FlatRegionNeighbor {
  const ImageF* color = nullptr;
  PinholeCamera camera;
};

// `color` (RGB in [0, 1]) and `photo_weight` are the reference's at working
// resolution, `camera` its camera at that size; `anchors` holds confident
// depths (metres, 0 = none) used to estimate each neighbour's exposure gain;
// `grid` is the sweep's label grid. Returns the prior label per pixel (NaN
// where none). Throws std::invalid_argument on bad options or sizes.
std::vector<float> FlatRegionPriors(const ImageF& color, const ImageF& photo_weight,
                                    const PinholeCamera& camera, const ImageF& anchors,
                                    const std::vector<FlatRegionNeighbor>& neighbors,
                                    const CostVolume& grid, const FlatRegionOptions& options,
                                    FlatRegionStats* stats = nullptr);

}  // namespace casual3d::depth
