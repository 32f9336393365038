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
// - where no warp sees both sides alike (a depth edge), the pair is not
//   joined, and no correction crosses it.
// The last term keeps d small, so a jump fades over about l on both sides
// and colours far from any seam keep their values. Pixels without a label
// take no part. Only the rows and columns that hold labelled pixels are
// solved (the columns wrap when labelled pixels reach all the way round).

#include "reconstruct/stitch/full_warps.h"
#include "reconstruct/stitch/stitch.h"

namespace casual3d::stitch {

// Evens out the seams of `out` (its rgb, label and depth_m as the stitch
// wrote them), a layer of `warps`; `front` is the front layer for the back
// layer's usability test (nullptr for the front layer).
void BlendSeams(const FullWarps& warps, const StitchedLayer* front, const StitchOptions& options,
                StitchedLayer* out);

}  // namespace casual3d::stitch
