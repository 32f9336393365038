#pragma once

// Full-resolution depth refinement (ours; the paper upsamples its MRF result
// and stops there). The sweep and the MRF run at the working resolution
// (half the photo's by default), where one pixel of disparity is two at full
// resolution; with a casual capture's baselines a label step is a fraction of
// a working pixel and far content needs a fraction of a label to be within a
// few percent of its depth. This step re-measures photo-consistency on the
// full-resolution photos around the upsampled depth map.
//
// For each of `steps` offsets delta spread evenly over [-search_labels,
// +search_labels] (in the sweep's label steps of inverse depth), every
// window pixel q is warped into each neighbour at its own current inverse
// depth plus delta: the window follows the current surface (slanted ground,
// a facade seen at an angle) instead of a fronto-parallel plane, and a window
// that straddles a depth edge samples each side at its own depth. The cost is
// the sweep's: 1 - ZNCC of the grey images over the (2r+1)^2 window, the mean
// of the best `best_k` neighbours that see the pixel, each capped at the best
// one's plus `occlusion_truncation`. Per pixel the offset of least cost,
// refined by a parabola through it and its two neighbours, moves the depth
// when it is an interior minimum and the pixel is textured (window variance
// weight var / (var + texture_sigma^2) at least `min_texture`); elsewhere the
// depth stays. The search never leaves +-search_labels: the MRF decides which
// surface a pixel shows, this step only locates it.
//
// Cost: steps x neighbours x pixels warps and window sums (the window sums
// run along rows and down columns, so the radius adds no cost per pixel);
// rows are streamed through cache-resident buffers as in the sweep.

#include <vector>

#include "format/image.h"
#include "format/status.h"
#include "reconstruct/depth/view.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

struct FullResRefineOptions {
  bool enabled = true;
  int window_radius = 5;             // Full-resolution pixels. [1, 15].
  double search_labels = 1.0;        // Half-width of the search, sweep label steps. (0, 8].
  // Depths tried, evenly spaced over +-search_labels (odd, so that the
  // current depth is one of them; docs/DECISIONS.md, "Dense: full-resolution
  // search with 7 offsets"). [3, 65].
  int steps = 7;
  int best_k = 3;                    // Neighbours averaged per pixel. [1, 16].
  double occlusion_truncation = 0.4; // As the sweep's. [0, 1].
  double ncc_epsilon = 2.5e-5;       // Variance added to both windows. [0, 1].
  double texture_sigma = 0.02;       // Texture weight var / (var + sigma^2). (0, 1].
  double min_texture = 0.3;          // Pixels with a lower texture weight keep their depth. [0, 1].

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("enabled", o.enabled, R::Any(), "Full-resolution depth search after upsampling");
    v.Field("window_radius", o.window_radius, R::Closed(1, 15), "ZNCC window radius, full-resolution pixels");
    v.Field("search_labels", o.search_labels, R::OpenClosed(0, 8), "Half-width of the search, sweep label steps");
    v.Field("steps", o.steps, R::Closed(3, 65), "Depths tried over +-search_labels (odd)");
    v.Field("best_k", o.best_k, R::Closed(1, 16), "Neighbours averaged per pixel");
    v.Field("occlusion_truncation", o.occlusion_truncation, R::Closed(0, 1), "As the sweep's occlusion_truncation");
    v.Field("ncc_epsilon", o.ncc_epsilon, R::Closed(0, 1), "Variance added to both windows");
    v.Field("texture_sigma", o.texture_sigma, R::OpenClosed(0, 1), "Texture weight var / (var + sigma^2)");
    v.Field("min_texture", o.min_texture, R::Closed(0, 1), "Pixels with a lower texture weight keep their depth");
    v.Require(o.steps % 2 == 1, "steps", "must be odd");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// Boundary relabelling (before the search above): near depth edges the
// upsampled map inherits the working resolution's window fattening (a pole's
// depth spread over the wall beside it, a tree's over the facade behind).
// Each textured pixel (colour-weighted window variance weight at least
// `min_texture`) within `radius` of a depth edge (two 4-neighbours whose
// inverse depths differ by more than `min_jump_labels`; a slope has no such
// step) whose depth is at least a label nearer than its (2 radius + 1)^2
// band window's farthest tests its own depth against two farther
// candidates: the colour-weighted median of the band window's farther
// depths (every 4th pixel both ways, weights
// exp(-|c_q - c_p|^2 / (2 sigma_color^2)): the surface of the pixel's own
// colour beyond the edge) and the farthest depth. The test is a
// colour-weighted ZNCC (adaptive support weights, Yoon and Kweon 2006) over
// the matching window, with the same weights, so that the pole's pixels
// hardly count in the wall pixel's window. The candidate of least cost
// (mean of the best best_k of the first `max_neighbors` neighbours, each
// capped at the best one's plus occlusion_truncation) wins when it beats the
// current depth's cost by `min_gain` (a current cost below min_gain skips
// the candidates: none can win). Only farther candidates: fattening moves
// the near side's depth outwards.
struct BoundaryRelabelOptions {
  bool enabled = true;
  // Full-resolution pixels: how far the working resolution's fattening
  // (the sweep's window radius plus the edge median's radius, doubled for the
  // working scale of 0.5) and the upsampling's reach. 20 was set with the
  // earlier 5x5 window (2 + 8, doubled); with the 7x7 window the sum is 22.
  // [1, 32].
  int radius = 20;
  // The window: the pixels at multiples of window_step from the centre (both
  // ways, the centre included) within window_radius of it. 6 and 2 (49
  // samples over 13x13 pixels) against 5 and 1 (121 over 11x11): 2.5 times
  // fewer samples.
  int window_radius = 6;          // Full-resolution pixels. [1, 15].
  int window_step = 2;            // [1, window_radius].
  double min_jump_labels = 3.0;   // [0, 1000].
  double sigma_color = 0.06;      // RGB distance. (0, 10].
  double min_gain = 0.05;         // Cost improvement needed to switch. [0, 1].
  int best_k = 2;                 // [1, 16].
  int max_neighbors = 12;         // Neighbours tested (the sweep's first ones). [1, 16].
  double occlusion_truncation = 0.4;  // [0, 1].
  double ncc_epsilon = 2.5e-5;    // [0, 1].
  double texture_sigma = 0.02;    // Texture weight var / (var + sigma^2). (0, 1].
  double min_texture = 0.1;       // [0, 1].

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("enabled", o.enabled, R::Any(), "Full-resolution relabelling of fattened depth edges");
    v.Field("radius", o.radius, R::Closed(1, 32), "Reach from a depth edge, full-resolution pixels");
    v.Field("window_radius", o.window_radius, R::Closed(1, 15), "Window radius, full-resolution pixels");
    v.Field("window_step", o.window_step, R::AtLeast(1), "Window sample spacing, pixels");
    v.Field("min_jump_labels", o.min_jump_labels, R::Closed(0, 1000), "Depth jump that makes an edge, labels");
    v.Field("sigma_color", o.sigma_color, R::OpenClosed(0, 10), "Colour sigma of the window weights, RGB distance");
    v.Field("min_gain", o.min_gain, R::Closed(0, 1), "Cost improvement needed to switch");
    v.Field("best_k", o.best_k, R::Closed(1, 16), "Neighbours averaged per pixel");
    v.Field("max_neighbors", o.max_neighbors, R::Closed(1, 16), "Neighbours the boundary relabelling tests (the sweep's first ones)");
    v.Field("occlusion_truncation", o.occlusion_truncation, R::Closed(0, 1), "As the sweep's occlusion_truncation");
    v.Field("ncc_epsilon", o.ncc_epsilon, R::Closed(0, 1), "Variance added to both windows");
    v.Field("texture_sigma", o.texture_sigma, R::OpenClosed(0, 1), "Texture weight var / (var + sigma^2)");
    v.Field("min_texture", o.min_texture, R::Closed(0, 1), "Pixels with a lower texture weight keep their depth");
    v.Require(o.window_step <= o.window_radius, "window_step", "must not exceed window_radius");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// One neighbour: its full-resolution grey image and camera.
struct RefineNeighbor {
  const ImageF* gray = nullptr;
  PinholeCamera camera;
};

struct FullResRefineStats {
  long long refined = 0;   // Pixels whose depth moved.
  long long textured = 0;  // Pixels with texture weight >= min_texture.
};

// `gray` is the reference photo's grey image at full resolution, `camera`
// its camera at that size, `depth` the depth map to refine (same size,
// metres, > 0). `inv_step` is the sweep's label step of inverse depth (1/m).
// Returns the refined depth. Throws std::invalid_argument on bad options or
// sizes.
ImageF RefineFullResolution(const ImageF& gray, const PinholeCamera& camera, const ImageF& depth,
                            const std::vector<RefineNeighbor>& neighbors, double inv_step,
                            const FullResRefineOptions& options, int num_threads = 1,
                            FullResRefineStats* stats = nullptr);

// `color` is the reference photo at full resolution (RGB in [0, 1]), `gray`
// its grey image, `depth` the map to relabel. Returns the relabelled map;
// `changed` (optional) receives the number of pixels that switched.
ImageF RelabelBoundaries(const ImageF& color, const ImageF& gray, const PinholeCamera& camera,
                         const ImageF& depth, const std::vector<RefineNeighbor>& neighbors, double inv_step,
                         const BoundaryRelabelOptions& options, int num_threads = 1,
                         long long* changed = nullptr);

}  // namespace casual3d::depth
