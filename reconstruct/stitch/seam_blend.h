#pragma once

// Seams of a stitched layer evened out in the gradient domain.
//
// A stitched pixel's colour is the mean of the warps blended into it
// (full_warps.h, BlendMembers). Where that set changes between neighbours
// (the border of a label, or a warp's depth leaving the blend tolerance),
// the colour jumps by the difference of the photos' exposures, white
// balance or vignetting: in a sky or on a wall, a patchwork of hard edges.
//
// The layer's colour f becomes f + d, where d minimises
//   sum over neighbour pairs (p, q) of (d_q - d_p - r_pq)^2 + sum over p of d_p^2 / l^2
// (ScreenedPoissonSolver, per channel) with l = seam_blend_length * width pixels:
// - where p and q blend the same warps, r_pq = 0: every colour difference
//   inside a set (texture, edges) is kept;
// - where the sets differ, the target difference is that of the warps both
//   sets hold that see one surface across the pair (unstretched, s <= 0.2,
//   and their own depths within 3%), each warp's colour at q minus its own
//   at p, weighted as the blending weighs them: r_pq = that minus
//   (f_q - f_p). The photos that see both sides give the difference without
//   the jump between photos. Only where that difference is at most 6 levels
//   in every channel (a smooth surface: sky, a wall) is it taken; in texture
//   a jump hides, and the warps' differences, off by their registration,
//   would spread noise: r_pq = 0 there;
// - where the sets differ and no warp they share sees both sides alike (a
//   depth edge), the pair is not joined, and no correction crosses it. A
//   depth edge inside one set (the same photos on both sides) stays joined,
//   with r_pq = 0.
// Sets are compared by a 64-bit hash of their photos' numbers; two sets that
// collide would count as one (their pair keeps f's step).
// The last term keeps d small, so a jump fades over about l on both sides
// and colours far from any seam keep their values. Pixels without a label
// take no part. Only the rows and columns that hold labelled pixels are
// solved (the columns wrap when labelled pixels reach all the way round).

#include "reconstruct/stitch/full_warps.h"
#include "reconstruct/stitch/stitch.h"

namespace casual3d::stitch {

// The part of a layer that is solved: rows y0 .. y0 + height - 1 and the
// width columns from x0 on (mod the layer's width).
struct SeamWindow {
  int x0 = 0, y0 = 0, width = 0, height = 0;
  bool wrap = false;  // Every column is in it, and the last joins the first.
};

// The rows and columns that hold labelled pixels (label >= 0): every column
// but the longest run, cyclically, of columns without any. False if no pixel
// is labelled.
bool FindSeamWindow(const Image<int16_t>& label, SeamWindow* win);

// Evens out the seams of `out` (its rgb and label as the stitch wrote them,
// with blend_depth_tolerance > 0), a layer of `warps`; `keys` holds, for each
// labelled pixel, the BlendKey of its BlendMembers (as the stitch blended
// it); `front` is the front layer for the back layer's usability test
// (nullptr for the front layer).
void BlendSeams(const FullWarps& warps, const StitchedLayer* front, const StitchOptions& options,
                const Image<uint64_t>& keys, StitchedLayer* out);

}  // namespace casual3d::stitch
