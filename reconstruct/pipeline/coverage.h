#pragma once

// How well a layer of the 3D photo covers what the photos saw: the photos'
// field of view in the central panorama, and the holes of the front layer
// inside it (the requirement: no hole larger than 1% of the field of view).
//
// Field of view: panorama pixel p is inside when the 3D point along p's ray
// at distance r(p) from the panorama centre projects inside at least one
// photo (pinhole part of its camera, in front of it). r(p) is the layer's own
// depth where the layer has a node, else the depth of the nearest node (in
// the image plane), so that the field of view follows the photos' parallax;
// `reference_depth_m` (the median depth of the layer's nodes by default)
// only serves an empty layer.
//
// Holes: 4-connected components of pixels inside the field of view without a
// node; columns wrap around at +-180 degrees. Areas are solid angles (an
// equirectangular pixel at latitude lat covers cos(lat) times the solid angle
// of an equatorial one), so that fractions do not depend on where the photos
// look.

#include <cstdint>
#include <vector>

#include "format/equirect.h"
#include "format/image.h"
#include "format/two_layer.h"
#include "reconstruct/geometry/camera.h"
#include "reconstruct/geometry/pose.h"
#include "reconstruct/warp/warp.h"

namespace casual3d::pipeline {

struct CoverageView {
  geometry::Camera camera;  // Its pinhole part is used.
  geometry::Pose pose;      // World to camera.
};

struct CoverageStats {
  int64_t fov_pixels = 0;         // Panorama pixels inside the field of view.
  double fov_steradians = 0.0;    // Their solid angle.
  double covered_fraction = 0.0;  // Solid angle with a node / field of view, [0, 1].
  int num_holes = 0;              // Components of uncovered pixels inside the field of view.
  int64_t hole_pixels = 0;        // Pixels in all of them.
  int64_t largest_hole_pixels = 0;
  // Solid angle of the largest hole / field of view, [0, 1].
  double largest_hole_fraction = 0.0;
  // The same over holes that do not touch the border of the field of view
  // (true holes, as opposed to ragged edges of the photos' footprints).
  int num_interior_holes = 0;
  double largest_interior_hole_fraction = 0.0;
  double reference_depth_m = 0.0;  // Depth used where the layer has no node.
};

// The field-of-view mask (width x height x 1; 255 inside, 0 outside) of
// `views` for `layer` of `pano`, as described above. `reference_depth_m` <= 0
// means the median depth of the layer's nodes (1 m for an empty layer).
// `num_threads`: 0 = all cores.
Image8 FieldOfViewMask(const TwoLayerPanorama& pano, int layer,
                       const std::vector<CoverageView>& views, double reference_depth_m = 0.0,
                       int num_threads = 0, double* used_reference_depth_m = nullptr);

// The same for a layer given as its depth (one channel, width = 2 height;
// pixels with depth > 0 are its nodes), e.g. a stitched layer before fusion.
Image8 FieldOfViewMask(const ImageF& depth_m, const PanoramaFrame& frame,
                       const std::vector<CoverageView>& views, double reference_depth_m = 0.0,
                       int num_threads = 0, double* used_reference_depth_m = nullptr);

// The photos' footprint: the union of the panorama pixels their front warps
// cover (width x height x 1; 255 inside). Unlike FieldOfViewMask it needs no
// guess of the depth in gaps: it holds exactly where the photos' surfaces land
// (stretched triangles across depth edges included), so holes inside it are
// surfaces the photos saw that the layer lost. The ragged edge of a footprint
// (near leaves at a photo's border, with background never seen between them)
// is not a hole.
Image8 FootprintMask(const std::vector<warp::WarpedView>& warps, int width, int height);

// Fills the gaps of a stitched layer inside `mask` (same size; 255 inside)
// ring by ring from their rims: each ring's pixels take the depth and label
// of their farthest already filled 8-neighbour (where a ring touches a nearer
// and a farther surface, the farther one, the background, continues; of
// equally far ones a 4-neighbour). Colour: the pixel mirrored through the
// rim pixel the chain of sources started from, if that pixel had content at
// the filled depth (within 5%), so that the texture beside the rim continues
// into the gap; else the mean colour of the filled neighbours within 5% of
// that depth. A gap between
// two surfaces closes from both sides. Columns wrap. Gaps
// outside the mask, or with no filled pixel around them, stay empty.
// `label` may be empty. Returns the number of pixels filled.
int64_t FillGapsInside(const Image8& mask, Image8* rgb, ImageF* depth_m, Image<int16_t>* label);

// The holes of `layer` of `pano` inside `fov` (same size as the panorama).
// If `holes` is not null it receives a mask (255 = hole pixel).
CoverageStats MeasureHoles(const TwoLayerPanorama& pano, int layer, const Image8& fov,
                           Image8* holes = nullptr);

}  // namespace casual3d::pipeline
