#pragma once

// Front and back layer stitching (paper Sec. 4.4.2).
//
// Every pixel of the panorama picks one source photo (a label) among the
// photos' warps (reconstruct/warp). The labelling minimises an MRF energy by
// alpha expansion at a reduced resolution (512x256 in the paper), and the
// label map is then upsampled to the full resolution by an edge-aware vote.
// The front panorama is stitched first; its depth constrains the back stitch.
//
// The paper's list of terms was lost from its text; the terms here are
// (spec/stage-panorama.md gives the same with their reasons):
// Data term of label a at pixel p (kInfiniteCost where a has no warp at p):
//   lambda_stretch * s_a(p)                          stretched triangles (Eq. 6)
// + lambda_parallax * min(angle_a(p) / parallax_scale_deg, 1)
//       angle between the ray from the centre and the ray from photo a's
//       camera to the same 3D point: smaller means colour and occlusion closer
//       to what the centre sees
// + lambda_gc * max(0, 1 - support_a(p) / gc_min_support)
//       geometric consistency (Fig. 15): support is the number of other photos
//       whose warp at p has a depth within gc_depth_tolerance of a's depth
// + back only: kInfiniteCost if d_a(p) < front_depth(p) * (1 - back_tolerance):
//       a back surface is never in front of the front surface.
// Seam term between neighbours p, q with labels a != b:
//   lambda_seam_color * (|c_a(p) - c_b(p)| + |c_a(q) - c_b(q)|) / (2 * 255)   (mean over RGB)
// + lambda_seam_depth * min(1, (|log(d_a(p) / d_b(p))| + |log(d_a(q) / d_b(q))|) / (2 seam_depth_scale))
//   and lambda_seam_invalid instead where a or b has no warp at p or q.

#include <cstdint>
#include <string>
#include <vector>

#include "format/equirect.h"
#include "format/image.h"
#include "reconstruct/stitch/alpha_expansion.h"
#include "reconstruct/warp/warp.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::stitch {

struct StitchOptions {
  // Sec. 4.4.2: the labelling is solved at this size (width = 2 * height).
  int solve_width = 512;
  int solve_height = 256;

  double lambda_stretch = 2.0;        // Cost per unit stretch penalty.
  double lambda_parallax = 0.5;       // Cost at parallax_scale_deg and beyond.
  double parallax_scale_deg = 10.0;   // Degrees; > 0.
  double lambda_gc = 1.0;             // Cost of a pixel with no support; 0 disables GC.
  double gc_depth_tolerance = 0.03;   // Relative depth agreement for support; (0, 1).
  int gc_min_support = 2;             // Supporting photos for zero GC cost; >= 1.
  double lambda_seam_color = 1.0;     // Seam cost per unit mean absolute colour difference.
  double lambda_seam_depth = 1.0;     // Seam cost of a depth step of seam_depth_scale or more.
  double seam_depth_scale = 0.05;     // Relative depth step that costs lambda_seam_depth; > 0.
  double lambda_seam_invalid = 4.0;   // Seam next to a pixel one label cannot show.
  double back_tolerance = 0.02;       // Back may be this much (relative) in front of the front.

  // Upsampling of labels: a full-resolution pixel chooses among the labels of
  // the (2 r + 1)^2 solve-resolution pixels around it.
  int upsample_radius = 1;
  double upsample_sigma_color = 20.0;  // 8-bit colour units; > 0.
  // Blending: a pixel's colour is the mean, and its depth the geometric
  // mean, of the warps (of this layer) whose depth there is within this
  // relative tolerance of the chosen label's, each weighted by exp(-6 s)
  // against stretched fragments: exposure differences and seams average
  // out, and so does the depth maps' independent noise. The label stays the
  // chosen photo (or, on the front layer, the one front_support picks). 0
  // keeps the chosen label's colour and depth alone, and turns front_support
  // off with it.
  double blend_depth_tolerance = 0.03;
  // Front layer: a pixel whose label's surface lies behind a nearer one that
  // at least this many unstretched warps agree on (within
  // blend_depth_tolerance) takes the nearest such surface: the labelling,
  // solved at a fraction of the resolution, loses thin structures that only
  // some photos' depth maps hold at a pixel. 0 keeps the label's; 1 (one
  // depth map's floater would win) is refused. Needs blend_depth_tolerance > 0.
  int front_support = 2;
  // Seams: where the set of blended warps changes from one pixel to the next
  // (a label's border, or a warp's depth leaving the tolerance), the colour
  // may jump by the photos' exposure difference. The jumps are evened out by
  // a correction that keeps every other colour difference and stays near the
  // blended colours (a screened Poisson problem, seam_blend.h); a jump fades
  // over about this fraction of the panorama width on both sides. 0: off;
  // off too with blend_depth_tolerance 0 (every set is then one photo).
  double seam_blend_length = 1.0 / 32;

  AlphaExpansionOptions solver;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("solve_width", o.solve_width, R::AtLeast(2), "Width the labelling is solved at, pixels (Sec. 4.4.2)");
    v.Field("solve_height", o.solve_height, R::AtLeast(1), "Height the labelling is solved at: width / 2");
    v.Field("lambda_stretch", o.lambda_stretch, R::AtLeast(0), "Cost per unit stretch penalty");
    v.Field("lambda_parallax", o.lambda_parallax, R::AtLeast(0), "Cost at parallax_scale_deg and beyond");
    v.Field("parallax_scale_deg", o.parallax_scale_deg, R::Above(0), "Parallax that costs lambda_parallax, degrees");
    v.Field("lambda_gc", o.lambda_gc, R::AtLeast(0), "Cost of a pixel with no support; 0 disables GC");
    v.Field("gc_depth_tolerance", o.gc_depth_tolerance, R::Open(0, 1), "Relative depth agreement for support");
    v.Field("gc_min_support", o.gc_min_support, R::AtLeast(1), "Supporting photos for zero GC cost");
    v.Field("lambda_seam_color", o.lambda_seam_color, R::AtLeast(0), "Seam cost per unit mean absolute colour difference");
    v.Field("lambda_seam_depth", o.lambda_seam_depth, R::AtLeast(0), "Seam cost of a depth step of seam_depth_scale or more");
    v.Field("seam_depth_scale", o.seam_depth_scale, R::Above(0), "Relative depth step that costs lambda_seam_depth");
    v.Field("lambda_seam_invalid", o.lambda_seam_invalid, R::AtLeast(0), "Seam cost next to a pixel one label cannot show");
    v.Field("back_tolerance", o.back_tolerance, R::ClosedOpen(0, 1), "Back may be this much (relative) in front of the front");
    v.Field("upsample_radius", o.upsample_radius, R::Closed(0, 4), "Label upsampling radius, solve-resolution pixels");
    v.Field("upsample_sigma_color", o.upsample_sigma_color, R::Above(0), "Label upsampling colour sigma, 8-bit units");
    v.Field("blend_depth_tolerance", o.blend_depth_tolerance, R::ClosedOpen(0, 1),
            "Colour and depth are the means of the warps within this relative depth of the label's; 0: the label's alone");
    v.Field("front_support", o.front_support, R::AtLeast(0),
            "Front pixels take the nearest surface this many unstretched warps agree on (within the blend "
            "tolerance, so off with it); 0: the label's");
    v.Field("seam_blend_length", o.seam_blend_length, R::Closed(0, 1),
            "Colour jumps between the sets of blended photos fade over this fraction of the width (with the "
            "blend tolerance, so off with it); 0: off");
    v.Struct("solver", o.solver);
    v.Require(o.solve_width == 2 * o.solve_height, "solve_width", "must be 2 * solve_height");
    v.Require(o.front_support != 1, "front_support", "must be 0 (off) or at least 2: one warp alone is a floater");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// What the seam blend did to one layer (seam_blend.h).
struct SeamBlendStats {
  int64_t pairs_with_target = 0;  // Neighbour pairs whose jump was evened out.
  int64_t pairs_cut = 0;          // Pairs whose sets differ and share no warp that sees one surface.
  int iterations = 0;             // Of the solve, the largest of the three channels'.
  double relative_residual = 0.0; // Of the solve, the largest of the three channels'.
};

// One stitched layer at full resolution.
struct StitchedLayer {
  Image8 rgb;           // 3 channels.
  ImageF depth_m;       // Distance from the centre along the ray; 0 where empty.
  Image<int16_t> label; // Source photo index, -1 where empty.
  // The labelling at the solve resolution and its energy (for diagnostics).
  Image<int16_t> solve_label;
  ImageF solve_depth_m;  // Depth of the labelling at the solve resolution.
  double energy = 0.0;
  SeamBlendStats seam_blend;
};

// Where each photo's camera is, in the panorama frame.
struct ViewGeometry {
  Vec3d centre;  // Camera centre, panorama frame, metres.
};

// Stitches the front layer. `full` are the photos' warps at the output size,
// `coarse` the same photos warped at the solve size (same order).
StitchedLayer StitchFront(const std::vector<warp::WarpedView>& full,
                          const std::vector<warp::WarpedView>& coarse,
                          const std::vector<ViewGeometry>& views, int pano_width,
                          const StitchOptions& options);

// Stitches the back layer from the photos' back warps, constrained by the
// stitched front layer (the same output size).
StitchedLayer StitchBack(const std::vector<warp::WarpedView>& full,
                         const std::vector<warp::WarpedView>& coarse,
                         const std::vector<ViewGeometry>& views, const StitchedLayer& front,
                         const StitchOptions& options);

}  // namespace casual3d::stitch
