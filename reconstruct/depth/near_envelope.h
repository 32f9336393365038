#pragma once

// Near envelope from pruned anchors (Sec. 4.3.2, Fig. 4e-f).
//
// Propagation (Eq. 5): minimise sum_i w_i (x_i - x'_i)^2 + sum_(i,j) w_ij (x_i - x_j)^2
// over the 4-connected grid, with x' the anchors, w_ij = exp(-|c_i - c_j|^2 / (2 sigma_env^2))
// (Levin et al. 2004) and w_i = unary_scale * sigma_i^2 (+ unary_floor) at anchors, sigma_i^2
// the colour variance of the surrounding patch (Kopf et al. 2013). The normal
// equations (W + L) x = W x' are symmetric positive definite whenever one
// anchor exists; they are solved with Eigen's Jacobi-preconditioned conjugate
// gradient, started from the solution of the same problem on a 2x coarser
// grid (recursively, see coarse_levels; the coarse grid box-averages colour,
// sums anchor weights and weight-averages anchor values). We propagate
// inverse depth rather than depth: the sweep samples inverse depth
// uniformly, and interpolating inverse depth between a near and a far anchor
// stays nearer (more conservative for a lower bound) than interpolating
// depth.
//
// Final envelope: the propagated depth times `scale` (0.9), then a
// morphological minimum filter of diameter min_filter_fraction (about 3%) of
// the image diagonal.

#include "format/image.h"
#include "format/status.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

struct EnvelopeOptions {
  double sigma_env = 0.1;            // Sec. 4.3.2: colour affinity sigma, colour in [0, 1].
  double unary_scale = 250.0;        // Sec. 4.3.2: w_i = 250 sigma_i^2.
  double unary_floor = 0.01;         // Added to w_i so flat anchors still count. [0, 1e3].
  int variance_radius = 9;           // Sec. 4.3.2: 19x19 patch at 900x1350 (scaled by caller).
  double scale = 0.9;                // Sec. 4.3.2: envelope = scale * propagated. (0, 1].
  double min_filter_fraction = 0.03; // Sec. 4.3.2: min-filter diameter / image diagonal. [0, 0.5].
  double cg_tolerance = 1e-5;        // Relative residual of the conjugate gradient. (0, 0.1].
  int cg_max_iterations = 3000;      // [1, 100000].
  // Coarse-to-fine: the problem is first solved on up to this many 2x
  // coarser grids (down to 16 pixels a side), each solution upsampled as the
  // next finer level's initial guess. 0 = single level. [0, 16].
  int coarse_levels = 4;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("sigma_env", o.sigma_env, R::OpenClosed(0, 10), "Propagation colour affinity sigma, colour in [0, 1] (Sec. 4.3.2)");
    v.Field("unary_scale", o.unary_scale, R::OpenClosed(0, 1e6), "Anchor weight w_i = unary_scale sigma_i^2 (Sec. 4.3.2)");
    v.Field("unary_floor", o.unary_floor, R::Closed(0, 1e3), "Added to w_i so flat anchors still count");
    v.Field("variance_radius", o.variance_radius, R::Closed(1, 256), "Anchor variance patch radius at 900x1350");
    v.Field("scale", o.scale, R::OpenClosed(0, 1), "Envelope = scale * propagated depth (Sec. 4.3.2)");
    v.Field("min_filter_fraction", o.min_filter_fraction, R::Closed(0, 0.5), "Min-filter diameter / image diagonal");
    v.Field("cg_tolerance", o.cg_tolerance, R::OpenClosed(0, 0.1), "Relative residual of the conjugate gradient");
    v.Field("cg_max_iterations", o.cg_max_iterations, R::Closed(1, 100000), "Most conjugate gradient iterations");
    v.Field("coarse_levels", o.coarse_levels, R::Closed(0, 16), "Coarser grids solved first; 0 = single level");
  }
  Status Check() const { return util::CheckFields(*this); }
};

struct PropagationStats {
  int anchors = 0;
  int iterations = 0;
  double residual = 0.0;  // Relative residual reached.
};

// Propagates the anchors of `anchors_depth` (metres, 0 = none) over the
// image guided by `color` (RGB in [0, 1], same size). Returns a dense depth
// map (metres). With no anchor at all, returns an empty image.
ImageF PropagateAnchors(const ImageF& anchors_depth, const ImageF& color,
                        const EnvelopeOptions& options, PropagationStats* stats = nullptr);

// scale * propagated, then the minimum filter. Returns the envelope (metres).
ImageF FinalizeEnvelope(const ImageF& propagated, const EnvelopeOptions& options);

// Morphological minimum filter with a square window of odd side `diameter`.
ImageF MinFilter(const ImageF& image, int diameter);

}  // namespace casual3d::depth
