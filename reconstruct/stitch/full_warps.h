#pragma once

// The full-resolution warps of one layer as the stitch reads them after the
// labelling: which warps a pixel may take, and which are blended into it.

#include <cstdint>
#include <utility>
#include <vector>

#include "reconstruct/stitch/stitch.h"
#include "reconstruct/warp/warp.h"

namespace casual3d::stitch {

// How strongly label upsampling avoids stretched fragments: a fully stretched
// one (s = 1) weighs exp(-6), about 0.25%, of an unstretched one.
constexpr double kUpsampleStretchWeight = 6.0;

// Fragments more stretched than this (triangles across a photo's depth edge,
// warp.h) neither propose nor support a front surface (NearestSupported in
// stitch.cc) nor give a seam's colour difference (seam_blend.h). 0.5 let two depth
// maps' fattened edges against the sky (stretch about 0.4) hold up a floater
// in sceaux's sky; fern's leaflets are held by unstretched fragments.
constexpr float kMaxSupportStretch = 0.2f;

// One layer's full-resolution warps, as the label upsampling and the blending
// read them.
struct FullWarps {
  bool back;
  const std::vector<warp::WarpedView>& full;
  int width;  // Of the panorama.
  double back_tolerance;

  const warp::WarpedLayer& layer(int l) const { return back ? full[l].back : full[l].front; }
  // Whether label l's warp has a depth at pixel (x, y) (its crop coordinates
  // in lx, ly) that this layer may take: for the back layer, not nearer than
  // the front.
  bool Usable(int l, int x, int y, float front_depth, int* lx, int* ly) const {
    const warp::WarpedLayer& w = layer(l);
    if (!w.ToCrop(x, y, width, lx, ly)) return false;
    const float d = w.depth_m.at(*lx, *ly);
    if (!(d > 0)) return false;
    return !(back && front_depth > 0 && d < front_depth * (1.0 - back_tolerance));
  }
};

// The warps blended into pixel (x, y) of a layer whose label there is `best`:
// every warp usable there (for the back layer, not in front
// of the front) whose depth lies within blend_depth_tolerance of best's, with
// its weight exp(-6 s) against stretched fragments; best itself always
// counts. `members` gets (warp, weight) pairs in warp order.
void BlendMembers(const FullWarps& warps, int best, int x, int y, float front_depth,
                  const StitchOptions& options, std::vector<std::pair<int, double>>* members);

// A 64-bit hash (FNV-1a) of the warps' numbers in `members`: equal sets give
// equal keys (two sets that collide would count as one).
uint64_t BlendKey(const std::vector<std::pair<int, double>>& members);

}  // namespace casual3d::stitch
