#pragma once

// Closing tears (spec/stage-panorama.md, "Sealing tears"): after fusion, a
// pixel quad whose four corners have front nodes should be closed seen from
// the centre (format/mesh_builder.h, QuadCoverage). Fusion leaves some open:
// on noisy but continuous surfaces a link is cut (depth ratio between
// tau_grazing and tau_dratio, not smooth) and a hallucinated back node takes
// the link slot the front surface needed, or the back layer could not grow
// behind a cut because the pixel already held another back node. Each such
// quad is then seen as a hole from everywhere, the centre included.
//
// The pass visits every open quad and tries small local edits:
//   - link two nodes across one of the quad's edges whose depth ratio is
//     above min_link_ratio (front to front, back to back, or across layers),
//     replacing the links those two link slots held;
//   - extend the farther surface behind a nearer corner: a back node at that
//     corner (where it has none) with the depth and colour of a farther node
//     of the quad, linked to every node of its neighbours within tau_dratio.
// Where three surfaces meet behind a foreground edge (a near branch over a
// wall and the sky), two layers cannot hold them all and no such edit closes
// the quad; a second round then also links two nodes across any depth step
// if both lie clearly behind the quad's nearest front node (depth above
// nearest / tau_dratio): a thin sheet hidden behind the foreground from the
// centre, instead of a hole seen from everywhere.
// A third round closes continuous front surfaces (four front corners within
// continuous_ratio in depth) whose own triangles leave a quad open: from the
// centre the back node behind such a quad hides the gap, but a viewer who
// moves sees through it. Its score keeps everything closed from the centre.
// A last round does the same for the back layer: quads whose four corners
// have back nodes that its own triangles leave open (noisy depth behind an
// edge) get links within one surface, scored so that nothing seen from the
// centre opens.
// An edit is kept when it closes more quarters of the quads around the
// changed pixels than it opens; the best edit of each quad is kept, links of
// nearly equal depth and back-layer extensions preferred to links across
// larger depth steps. Passes repeat until nothing changes (at most
// max_passes). The result still passes TwoLayerPanorama::Validate().

#include <cstdint>
#include <string>

#include "format/two_layer.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::fuse {

struct SealOptions {
  // Nodes whose depth ratio (min / max) is above this may be linked to close
  // a quad; (0, 1). The paper's tau (Sec. 4.4.3).
  double min_link_ratio = 0.75;
  // Depth ratio above which a back-layer extension links to a neighbour;
  // (min_link_ratio, 1). Fusion's tau_dratio.
  double tau_dratio = 0.95;
  int max_passes = 4;  // [1, 32].
  // Four front nodes whose depths lie within this ratio (min / max) of each
  // other are one continuous surface, whose quad the front layer's own
  // triangles should close; (0, 1). The warp's min_edge_depth_ratio.
  double continuous_ratio = 0.9;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("min_link_ratio", o.min_link_ratio, R::Open(0, 1), "Depth ratio above which nodes may be linked to close a quad");
    v.Field("tau_dratio", o.tau_dratio, R::ClosedOpen(0, 1), "Depth ratio above which a back-layer extension links");
    v.Field("max_passes", o.max_passes, R::Closed(1, 32), "Sealing passes");
    v.Field("continuous_ratio", o.continuous_ratio, R::Open(0, 1), "Front nodes within this depth ratio are one surface");
    v.Require(o.tau_dratio > o.min_link_ratio, "tau_dratio", "must exceed min_link_ratio");
  }
  Status Check() const { return util::CheckFields(*this); }
};

struct SealStats {
  int64_t open_quads_before = 0;  // Quads with four front corners, not closed.
  int64_t open_quads_after = 0;
  // Quads with four back corners that the back layer leaves open.
  int64_t back_open_quads_before = 0;
  int64_t back_open_quads_after = 0;
  // Quads of continuous front surfaces that the front layer's own triangles
  // leave open (closed from the centre by back nodes only).
  int64_t front_surface_open_quads_before = 0;
  int64_t front_surface_open_quads_after = 0;
  int64_t links_made = 0;
  int64_t back_nodes_added = 0;
};

// Seals `pano` in place. Normals of added back nodes are left zero (the
// normals stage computes them). Throws std::invalid_argument for bad options.
SealStats SealTears(TwoLayerPanorama* pano, const SealOptions& options = SealOptions());

// Quads whose four corners have front nodes and that are not closed seen
// from the centre.
int64_t CountOpenQuads(const TwoLayerPanorama& pano);

}  // namespace casual3d::fuse
