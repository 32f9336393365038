#pragma once

// Levels of detail of a two-layer panorama (spec/package.md, "Levels of
// detail"): each coarser level halves width and height.

#include "format/status.h"
#include "format/two_layer.h"

namespace casual3d::encoder {

// The next coarser level of `fine` (whose width and height must be even):
// coarse node (x, y, layer l) exists iff fine node (2x, 2y, l) exists and takes
// its depth, normal and label. Its colour is the mean of the same-layer fine
// nodes of the 2x2 block whose depth is within 5% of it. Its link in direction d
// is the two-step path of fine links from (2x, 2y, l) in direction d, so links
// stay mutual and depth edges stay open. Returns kInvalidArgument for odd sizes.
StatusOr<TwoLayerPanorama> HalvePanorama(const TwoLayerPanorama& fine);

}  // namespace casual3d::encoder
