#pragma once

// The steps of FlatRegionPriors (flat_regions.h), each on its own so that it
// can be tested: segmentation into groups of flat pixels, boundary points
// with their colour edges, edge depths and ownership, a plane per group,
// adoption of a neighbour's plane and the priors. Internal to the depth
// library.

#include <array>
#include <cstdint>
#include <vector>

#include "format/image.h"
#include "reconstruct/depth/flat_regions.h"

namespace casual3d::depth::flat {

// Flat pixels segmented into regions of nearly constant colour, regions of
// similar colour that a thin occluder separates joined into groups. Group
// ids index `area` and `colour`; an id that is not a group has area 0.
struct FlatGroups {
  std::vector<int> group;                    // Per pixel (row-major): group id, -1 none.
  std::vector<long long> area;               // Pixels per group id.
  std::vector<std::array<float, 3>> color;  // Mean colour per group id.
  int size() const { return static_cast<int>(area.size()); }
};

// Step 1: regions grown among the pixels with w_photo below max_photo_weight
// (color_step to a 4-neighbour, color_spread to the region's mean; regions
// under min_region_pixels dropped), joined across at most merge_gap pixels
// along the axes when their means lie within merge_color. Empty when no
// region is found.
FlatGroups SegmentFlatGroups(const ImageF& color, const ImageF& photo_weight,
                             const FlatRegionOptions& options);

// Offsets (pixels along the outward normal) of the colour profile across an
// edge that the edge test matches.
constexpr int kProfile = 11;
constexpr float kProfileStart = -2.5f, kProfileStep = 0.5f;

struct EdgePoint {
  float x = 0, y = 0;    // The colour edge (pixel-index coordinates).
  float profile[kProfile] = {};  // min(1, colour difference to the region / scale) across it.
  float scale = 1;       // The colour difference that saturates the profile.
  float nx = 0, ny = 0;  // Outward unit normal.
  float label = 0;       // Edge depth as a fractional label.
  // Whose edge it is, from the surface just beyond it (Classify).
  enum class Kind { kUnknown, kOwned, kAtBeyond, kThin } kind = Kind::kUnknown;
  bool owned() const { return kind == Kind::kOwned; }
};

// The boundary points of every group of at least `min_area` pixels, with
// their outward normals (from the smoothed group mask) and colour edges
// located to a fraction of a pixel; points without a clear colour edge
// within 6 pixels, or whose profile leaves the image, are left out.
std::vector<std::vector<EdgePoint>> FindEdgePoints(const ImageF& color, const FlatGroups& groups,
                                                   long long min_area,
                                                   const FlatRegionOptions& options);

struct Plane {
  double a = 0, b = 0, c = 0;  // label = a x + b y + c.
  double At(double x, double y) const { return a * x + b * y + c; }
};

struct PlaneFit {
  bool ok = false;
  Plane plane;
};

// Step 4: a group of at least `min_area` pixels without a plane of its own
// takes that of a fitted group of similar colour (within 2 merge_color)
// whose bounding box lies within adopt_distance pixels, when its own
// measured edges agree (at most 1 - behind_fraction of them in front of the
// plane), the one its edges touch most.
void AdoptPlanes(const FlatGroups& groups, int width, int height,
                 const std::vector<std::vector<EdgePoint>>& measured,
                 const std::vector<int>& fitted_groups, const std::vector<int>& unfitted_groups,
                 const FlatRegionOptions& options, std::vector<PlaneFit>* fits);

// Step 5: the prior label (the plane, clamped to [0, num_labels - 1]) over
// each fitted group's pixels and the pixels of its colour (within
// color_spread) connected to it with w_photo below extend_max_photo_weight.
// NaN elsewhere. Counts fitted groups and pixels into `stats`.
std::vector<float> AssignPriors(const ImageF& color, const ImageF& photo_weight,
                                const FlatGroups& groups, const std::vector<PlaneFit>& fits,
                                int num_labels, const FlatRegionOptions& options,
                                FlatRegionStats* stats);

}  // namespace casual3d::depth::flat
