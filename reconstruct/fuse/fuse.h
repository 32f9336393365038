#pragma once

// Two-layer fusion (paper Sec. 4.4.3, Fig. 9): turns the stitched front and
// back colour-and-depth panoramas into one two-layer graph.
//   1. Remove redundant back nodes: a back node whose depth is within the
//      ratio tau_dratio of its front node's (min/max > tau) repeats the front
//      surface and is dropped. (The paper writes d(f)/d(b) < tau for "too
//      similar"; with d(f) <= d(b) similar means a ratio near 1, so the test
//      here is d(f)/d(b) > tau.)
//   2. Recompute connectivity: for each pair of 4-neighbouring pixels, all
//      front/back node pairs are sorted by depth ratio, most similar first; the
//      most similar pair is linked if it is one surface (ratio above tau, or
//      above tau_grazing and smooth), and the other pair too if it does not
//      cross the first (front-front with back-back).
//   3. Grow the back layer ring by ring: a node without a link towards a
//      neighbour spawns a candidate there with the mean depth and colour of its
//      spawners; the candidate is kept where the neighbour has a front node
//      clearly in front of it (ratio <= tau) and no back node, only if it
//      links to a spawner, and only within the rings a moving eye can open
//      behind that front node (rings * (1 - df / db) + 1). Kept nodes are
//      hallucinated, labelled B.
//   4. Remove colour fringes: the B label spreads from B nodes along links onto
//      front nodes for a few rings; those front nodes take the back stitch's
//      colour where the back stitch saw the same surface (the redundant back
//      node of step 1), which is free of foreground colour bleeding.
// Normals are left zero (the normals stage fills them).

#include <string>

#include "format/equirect.h"
#include "format/image.h"
#include "format/two_layer.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::fuse {

struct FuseOptions {
  // Depth ratio (min / max) above which two nodes are one surface; (0, 1).
  // Sec. 4.4.3 uses 0.75 at 8192 px; at that ratio, edges of up to 33% in
  // depth (a tree 10 m in front of a wall at 12 m) would be closed and get no
  // back layer, so ratios below 0.95 link only where the surface is smooth
  // (tau_grazing). Above 0.9 because a reconstructed edge whose two depths
  // are each a few percent off can reach a ratio above 0.9 (measurements:
  // docs/DECISIONS.md, "Fusion: depth-ratio threshold 0.95").
  double tau_dratio = 0.95;
  // Neighbours whose depth ratio lies in (tau_grazing, tau_dratio] are linked
  // when the depths continue smoothly along the grid axis (a surface seen at a
  // grazing angle, such as the ground towards the horizon): the log-depth step
  // p -> q differs by at most smooth_tolerance from the step before p or after
  // q in the same layer. (0, tau_dratio].
  double tau_grazing = 0.75;
  double smooth_tolerance = 0.02;  // In log depth; >= 0.
  // Rings of back-layer growth, as a fraction of the panorama width (0.012
  // at 4096 px: 49 rings, 4.3 degrees: the disocclusion a head moved by 7.5%
  // of the foreground's depth opens in front of a far background; the
  // panorama stage bounds the viewing volume by it); [0, 0.25].
  double expansion_fraction = 0.012;
  // Rings of B-label propagation onto front nodes, fraction of the width (0.001 at 4096: 4); >= 0.
  double fringe_fraction = 0.001;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("tau_dratio", o.tau_dratio, R::Open(0, 1), "Depth ratio min / max above which two nodes are one surface");
    v.Field("tau_grazing", o.tau_grazing, R::Above(0), "Lower depth ratio linked where the surface continues smoothly");
    v.Field("smooth_tolerance", o.smooth_tolerance, R::AtLeast(0), "Log-depth step difference of a smooth surface");
    v.Field("expansion_fraction", o.expansion_fraction, R::Closed(0, 0.25), "Rings of back-layer growth, fraction of the width");
    v.Field("fringe_fraction", o.fringe_fraction, R::Closed(0, 0.05), "Rings of B-label propagation, fraction of the width");
    v.Require(o.tau_grazing <= o.tau_dratio, "tau_grazing", "must not exceed tau_dratio");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// Inputs: both layers at the same size (width = 2 * height), depth 0 where a
// layer has no content. Depth is the distance from the centre along the ray.
struct FuseInput {
  const Image8* front_rgb = nullptr;
  const ImageF* front_depth_m = nullptr;
  const Image8* back_rgb = nullptr;
  const ImageF* back_depth_m = nullptr;
  PanoramaFrame frame;
};

struct FuseStats {
  long front_nodes = 0;
  long back_nodes_in = 0;        // Back stitch pixels with content.
  long back_nodes_redundant = 0; // Removed in step 1.
  long back_nodes_hallucinated = 0;
  long front_nodes_relabelled = 0;  // Step 4.
  long links = 0;                   // Undirected links.
};

// Throws std::invalid_argument on mismatched or invalid inputs. The result
// passes TwoLayerPanorama::Validate().
TwoLayerPanorama Fuse(const FuseInput& input, const FuseOptions& options,
                      FuseStats* stats = nullptr);

}  // namespace casual3d::fuse
