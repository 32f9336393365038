#pragma once

// Plane-sweep cost volume (Sec. 4.3.1, Collins 1996): for each pixel of a
// reference photo and each of `num_depths` fronto-parallel planes spaced
// uniformly in inverse depth, the photo-consistency cost E_photo of Eq. 3
// against the neighbouring photos, and the per-pixel confidence w_photo.
//
// Photo-consistency (the paper's supplement is lost; our choice, see
// spec/stage-dense.md): zero-mean normalised cross-correlation (ZNCC) over a
// (2r+1)^2 window on the grey image, which is invariant to gain and offset
// (exposure changes). Per neighbour the cost is min(1, 1 - ZNCC) in [0, 1];
// the costs of the `best_k` best neighbours are averaged, each capped at the
// best one's plus `occlusion_truncation`, which tolerates partial occlusion
// (a surface hidden in some neighbours still matches in the others).
// w_photo = var / (var + texture_sigma^2) with var the reference window's
// intensity variance, weighted by colour similarity to the centre
// pixel: low in textureless regions, where ZNCC is noise, and on flat pixels
// whose window borrows its texture from a differently coloured neighbour.
// Window pixels that a neighbour does not see count as black.
//
// Cost: linear in pixels x planes x neighbours (window sums run along rows
// and down columns, so the radius only adds 2r adds per pixel and moment).
// Threads take groups of planes; each plane is streamed row by row through
// cache-resident rows (warp, window sums, ZNCC, best-k aggregation:
// sweep_kernels.h). Extra memory besides the volume: about 16 planes per
// thread.

#include <cstdint>
#include <limits>
#include <vector>

#include "format/image.h"
#include "format/status.h"
#include "reconstruct/depth/sweep_kernels.h"
#include "reconstruct/depth/view.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

struct SweepOptions {
  int num_depths = 220;         // Sec. 4.3.1: depth hypotheses. Range [2, 4096].
  // ZNCC window radius at working resolution, pixels: a (2r + 1)^2 window.
  // A smaller window fattens near objects less but matches less reliably
  // (docs/DECISIONS.md, "Dense: 7x7 ZNCC window"). [1, 15].
  int window_radius = 3;
  int best_k = 2;               // Neighbours averaged per pixel (best costs first). [1, 16].
  // Each of the best_k costs is capped at the best one's plus this before
  // the mean: a neighbour that sees the best neighbour's surface hidden (an
  // occluder in front of it, the far side of a partial rig) counts as a
  // fixed penalty rather than as its full cost, whose noise would pick the
  // label. In cost units (min(1, 1 - ZNCC), in [0, 1]): 1 = the plain mean,
  // 0 = the best neighbour's cost alone (measurements: docs/DECISIONS.md,
  // "Dense: occlusion truncation"). [0, 1].
  double occlusion_truncation = 0.4;
  double ncc_epsilon = 2.5e-5;  // Variance added to both windows (intensity^2); damps ZNCC of
                                // flat, noisy windows towards 0. [0, 1].
  double texture_sigma = 0.02;  // w_photo = var / (var + texture_sigma^2), intensity. (0, 1].
  // Colour sigma of the texture measure (RGB distance, colour in [0, 1]):
  // var is the window's grey variance with each window pixel weighted by
  // exp(-|c_q - c_p|^2 / (2 sigma^2)) against the centre's colour, so that it
  // measures the texture of the pixel's own surface. A flat pixel next to a
  // textured object (a blank wall beside a pole) gets a low w_photo although
  // its window, and so its ZNCC, is dominated by the object's edge (window
  // fattening). 0 = the plain window variance. [0, 10].
  double texture_color_sigma = 0.1;
  int num_threads = 0;          // 0 = all cores.

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("num_depths", o.num_depths, R::Closed(2, 4096), "Depth hypotheses over the sparse range (Sec. 4.3.1: 220)");
    v.Field("window_radius", o.window_radius, R::Closed(1, 15), "ZNCC window radius at working resolution (3: 7x7)");
    v.Field("best_k", o.best_k, R::Closed(1, 16), "Neighbours averaged per pixel (best costs first)");
    v.Field("occlusion_truncation", o.occlusion_truncation, R::Closed(0, 1),
            "Each of the best neighbours' matching costs is capped at the best one's plus this (1: plain mean)");
    v.Field("ncc_epsilon", o.ncc_epsilon, R::Closed(0, 1), "Variance added to both ZNCC windows, intensity^2");
    v.Field("texture_sigma", o.texture_sigma, R::OpenClosed(0, 1), "w_photo = var / (var + texture_sigma^2), intensity");
    v.Field("texture_color_sigma", o.texture_color_sigma, R::Closed(0, 10),
            "Colour sigma of the texture measure w_photo; 0 = plain window variance");
    v.Field("num_threads", o.num_threads, R::AtLeast(0), "Worker threads; 0 = all cores", util::Keyed::kNo);
  }
  Status Check() const { return util::CheckFields(*this); }
};

// Costs for every pixel and depth label, pixel-major so that one pixel's
// costs are contiguous (the MRF's access pattern). Label 0 is the nearest
// plane, label num_labels-1 the farthest.
struct CostVolume {
  int width = 0;
  int height = 0;
  int num_labels = 0;
  double inv_near = 0.0;    // 1 / near_m: inverse depth of label 0, 1/m.
  double inv_far = 0.0;     // 1 / far_m: inverse depth of the last label, 1/m.
  std::vector<float> cost;  // E_photo in [0, 1], index (y * width + x) * num_labels + k.
  ImageF photo_weight;      // w_photo per pixel in [0, 1].

  const float* Costs(int x, int y) const {
    return cost.data() + (static_cast<size_t>(y) * width + x) * num_labels;
  }
  // Inverse depth (1/m) of a possibly fractional label.
  double InvDepthOfLabel(double k) const {
    return inv_near + (inv_far - inv_near) * k / (num_labels - 1);
  }
  double DepthOfLabel(double k) const { return 1.0 / InvDepthOfLabel(k); }
  // Fractional label of a depth (metres), not clamped.
  double LabelOfDepth(double depth_m) const {
    return (1.0 / depth_m - inv_near) / (inv_far - inv_near) * (num_labels - 1);
  }
};

// The parts of the homography that the fronto-parallel plane Z_ref = d
// induces from `ref` to `neighbor` (Hartley & Zisserman, Sec. 13.1):
// x_n ~ a x_ref + (1/d) b with a = K_n R_rel K_ref^-1 and b = K_n t_rel
// (pixel coordinates in COLMAP's convention, view.h), in float for the kernels.
struct PlaneHomography {
  float a[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  float b[3] = {0, 0, 0};

  // Row y of the homography of the plane with inverse depth inv_d, with the
  // pixel-centre offsets (x + 0.5, y + 0.5) folded in (sweep::WarpRow's input).
  sweep::HomographyRow Row(int y, float inv_d) const {
    sweep::HomographyRow row;
    const float v = y + 0.5f;
    for (int c = 0; c < 3; ++c) {
      row.p0[c] = a[c][1] * v + a[c][2] + b[c] * inv_d + a[c][0] * 0.5f;
      row.step[c] = a[c][0];
    }
    return row;
  }

  // Homogeneous coordinate c of the reference pixel (x, y)'s centre on the
  // plane of inverse depth inv_d.
  float Homogeneous(int c, float x, float y, float inv_d) const {
    return a[c][0] * (x + 0.5f) + a[c][1] * (y + 0.5f) + a[c][2] + b[c] * inv_d;
  }

  // Neighbour pixel-index position (u, v) of the reference pixel (x, y)'s
  // centre on the plane of inverse depth inv_d; false behind the neighbour.
  bool Project(float x, float y, float inv_d, float* u, float* v) const {
    const float qz = Homogeneous(2, x, y, inv_d);
    if (!(qz > 1e-9f)) return false;
    *u = Homogeneous(0, x, y, inv_d) / qz - 0.5f;
    *v = Homogeneous(1, x, y, inv_d) / qz - 0.5f;
    return true;
  }

  // Project for n pixels at once, in a loop the compiler vectorises: NaN
  // in u and v for those behind the neighbour. The outputs must not overlap
  // the inputs.
  void ProjectMany(const float* __restrict x, const float* __restrict y, int n, float inv_d, float* __restrict u,
                   float* __restrict v) const {
    // The coefficients in locals: stores through u and v cannot change them.
    // The arithmetic is Homogeneous's, in the same order.
    float c[3][4];
    for (int r = 0; r < 3; ++r) {
      c[r][0] = a[r][0];
      c[r][1] = a[r][1];
      c[r][2] = a[r][2];
      c[r][3] = b[r] * inv_d;
    }
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (int i = 0; i < n; ++i) {
      const float xc = x[i] + 0.5f, yc = y[i] + 0.5f;
      const float qz = c[2][0] * xc + c[2][1] * yc + c[2][2] + c[2][3];
      const bool front = qz > 1e-9f;
      const float den = front ? qz : 1.0f;
      const float qx = c[0][0] * xc + c[0][1] * yc + c[0][2] + c[0][3];
      const float qy = c[1][0] * xc + c[1][1] * yc + c[1][2] + c[1][3];
      // Divisions outside the selection (den is never 0), so that the
      // compiler can vectorise the loop.
      const float ui = qx / den - 0.5f, vi = qy / den - 0.5f;
      u[i] = front ? ui : nan;
      v[i] = front ? vi : nan;
    }
  }
};
PlaneHomography ComputePlaneHomography(const PinholeCamera& ref, const PinholeCamera& neighbor);

class BufferPool;  // huge_pages.h

// Builds the cost volume of `ref` against `neighbors` (all at the working
// resolution, same size or not). Requires ref.range with 0 < near < far and at
// least one neighbour. Throws std::invalid_argument on bad options or input.
// With a `pool`, the volume's storage comes from it (give it back with
// BufferPool::Give when done).
CostVolume ComputeCostVolume(const DenseView& ref, const std::vector<const DenseView*>& neighbors,
                             const SweepOptions& options, BufferPool* pool = nullptr);

// Winner-takes-all (Sec. 4.3.2): per pixel, the depth (metres) of the label
// minimising E_photo, ignoring smoothness. Pixels where every label costs 1
// (seen by no neighbour) get depth 0 (invalid).
ImageF WinnerTakesAll(const CostVolume& volume, int num_threads = 0);

}  // namespace casual3d::depth
