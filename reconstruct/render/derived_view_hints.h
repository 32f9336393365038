#pragma once

// View hints (format/view_hints.h) derived from a two-layer panorama alone,
// for 3D photos that do not carry them (packages of version 1.0, panoramas
// made by hand): what the captured content is and how to look at it.
//
// Derivation, from the present front nodes only:
//  * Longitudes: a column of the panorama holds content when at least
//    max(1, height / 200) of its pixels have a front node (so that a few stray
//    nodes do not count). The content's longitude extent is the whole circle
//    minus the largest run of empty columns, taken around the +-180 degree
//    seam (content across the seam gives an extent with max > 180 or
//    min < -180); the whole circle when no column is empty.
//  * Latitudes: the rows from the first to the last that hold at least
//    max(1, c / 200) front nodes, c being the number of content columns.
//  * Direction: the middle of both extents (yaw normalised to [-180, 180];
//    yaw 0 when the content is the whole circle).
//  * Field of view (vertical): the largest that keeps a 4:3 view centred on
//    that direction within the extents, min(latitude extent,
//    2 atan(tan(longitude extent / 2) / (4/3))), clamped to [10, 120].
//  * Viewing volume: radius 0.06 times the 5th percentile of the front depths
//    (the bound the panorama stage puts on its own hints: an eye moved by 6%
//    of the near content's distance opens disocclusions the back layer's
//    growth fills; spec/stage-panorama.md, "View hints"); metric false.
// A panorama without front nodes gives the defaults of ViewHints with
// volume_radius 0.06 times the nearest depth of any node (or 0.1).

#include <cstdint>
#include <optional>
#include <vector>

#include "format/image.h"
#include "format/two_layer.h"
#include "format/view_hints.h"

namespace casual3d::render {

// Share of the 5th-percentile front depth used as the viewing volume's radius.
constexpr double kDerivedVolumeFraction = 0.06;

// The longitudes of the columns flagged in `column_has` (one flag per
// panorama column): the whole circle minus the largest circular run of
// unflagged columns, as [min, max] degrees with the middle in [-180, 180)
// (so content across the +-180 degree seam gives min < -180). False,
// leaving both untouched, when no column is flagged.
bool YawExtentOfColumns(const std::vector<uint8_t>& column_has, double* yaw_min_deg,
                        double* yaw_max_deg);

// The q-quantile (q in [0, 1]) of the present front depths, from at most
// about a million evenly spaced nodes; only nodes where `mask` (same size,
// non-zero inside) is set when it is given. 0 when there are none.
double FrontDepthQuantile(const TwoLayerPanorama& pano, double q, const Image8* mask = nullptr);

// The hints derived from `pano` as described above; always valid
// (ViewHints::Validate).
ViewHints DeriveViewHints(const TwoLayerPanorama& pano);

// `hints` when given and valid, else DeriveViewHints(pano). `derived`, if not
// null, says which.
ViewHints ResolveViewHints(const TwoLayerPanorama& pano, const std::optional<ViewHints>& hints,
                           bool* derived = nullptr);

}  // namespace casual3d::render
