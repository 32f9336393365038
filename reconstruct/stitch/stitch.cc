#include "reconstruct/stitch/stitch.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <utility>

#include "base/parallel_for.h"
#include "reconstruct/stitch/full_warps.h"
#include "reconstruct/stitch/seam_blend.h"

namespace casual3d::stitch {
namespace {

constexpr double kRadToDeg = 180.0 / kPi;

// The per-label data of one layer at the solve resolution, densely stored.
struct CoarseStack {
  int width = 0, height = 0, num_labels = 0;
  std::vector<float> depth;     // [label][pixel]; 0 = no warp.
  std::vector<float> log_depth; // [label][pixel].
  std::vector<float> stretch;   // [label][pixel].
  std::vector<uint8_t> rgb;     // [label][pixel][3].

  size_t at(int label, int pixel) const {
    return static_cast<size_t>(label) * width * height + pixel;
  }
};

void FillStack(const std::vector<warp::WarpedView>& views, bool back, int width, int height,
               CoarseStack* stack) {
  stack->width = width;
  stack->height = height;
  stack->num_labels = static_cast<int>(views.size());
  const size_t n = static_cast<size_t>(width) * height * views.size();
  stack->depth.assign(n, 0.0f);
  stack->log_depth.assign(n, 0.0f);
  stack->stretch.assign(n, 1.0f);
  stack->rgb.assign(3 * n, 0);
  for (int l = 0; l < stack->num_labels; ++l) {
    const warp::WarpedLayer& layer = back ? views[l].back : views[l].front;
    for (int cy = 0; cy < layer.height(); ++cy) {
      const int y = layer.y0 + cy;
      if (y < 0 || y >= height) continue;
      for (int cx = 0; cx < layer.width(); ++cx) {
        const float d = layer.depth_m.at(cx, cy);
        if (!(d > 0)) continue;
        const int x = WrapColumn(layer.x0 + cx, width);
        const size_t i = stack->at(l, y * width + x);
        stack->depth[i] = d;
        stack->log_depth[i] = std::log(d);
        stack->stretch[i] = layer.stretch.at(cx, cy);
        for (int c = 0; c < 3; ++c) stack->rgb[3 * i + c] = layer.rgb.at(cx, cy, c);
      }
    }
  }
}

double ParallaxDeg(const Vec3d& dir, double depth, const Vec3d& camera) {
  const double px = dir.x * depth, py = dir.y * depth, pz = dir.z * depth;
  const double qx = px - camera.x, qy = py - camera.y, qz = pz - camera.z;
  const double qn = std::sqrt(qx * qx + qy * qy + qz * qz);
  if (qn <= 0) return 180.0;
  const double c = (px * qx + py * qy + pz * qz) / (depth * qn);
  return std::acos(std::clamp(c, -1.0, 1.0)) * kRadToDeg;
}

// The data term of every label at every solve pixel (Sec. 4.4.2): stretch,
// parallax and, with lambda_gc, too few other photos agreeing on the depth.
// `front` (back layer only): a label nearer than the front layer is invalid.
void SetDataCosts(bool back, const CoarseStack& stack, const CoarseStack& front_stack,
                  const std::vector<ViewGeometry>& views, const StitchedLayer* front,
                  const StitchOptions& options, GridMrf* mrf) {
  const int sw = stack.width, sh = stack.height, L = stack.num_labels;
  const float tol = static_cast<float>(options.gc_depth_tolerance);
  base::ParallelFor(0, sh, base::ResolveThreads(0), [&](int64_t y64) {
    const int y = static_cast<int>(y64);
    for (int x = 0; x < sw; ++x) {
      const int p = y * sw + x;
      const Vec3d dir = EquirectPixelToDirection(x + 0.5, y + 0.5, sw, sh);
      const float front_depth = front ? front->solve_depth_m.at(x, y) : 0.0f;
      for (int l = 0; l < L; ++l) {
        const float d = stack.depth[stack.at(l, p)];
        if (!(d > 0)) continue;
        if (back && front_depth > 0 && d < front_depth * (1.0 - options.back_tolerance)) continue;
        double cost = options.lambda_stretch * stack.stretch[stack.at(l, p)];
        cost += options.lambda_parallax *
                std::min(1.0, ParallaxDeg(dir, d, views[l].centre) / options.parallax_scale_deg);
        if (options.lambda_gc > 0) {
          int support = 0;
          for (int k = 0; k < L && support < options.gc_min_support; ++k) {
            if (k == l) continue;
            const float dk = stack.depth[stack.at(k, p)];
            bool agrees = dk > 0 && std::abs(dk - d) <= tol * d;
            if (!agrees && back) {
              const float fk = front_stack.depth[front_stack.at(k, p)];
              agrees = fk > 0 && std::abs(fk - d) <= tol * d;
            }
            support += agrees;
          }
          cost += options.lambda_gc *
                  std::max(0.0, 1.0 - static_cast<double>(support) / options.gc_min_support);
        }
        mrf->data_cost(p, l) = static_cast<float>(cost);
      }
    }
  });
}

// The seam cost of labels a and b on the solve pixels p and q: colour and
// log-depth differences of the two warps there, or lambda_seam_invalid where
// either lacks a depth.
float SeamCost(const CoarseStack& stack, const StitchOptions& options, float inv_scale, int p, int q,
               int a, int b) {
  const size_t ap = stack.at(a, p), bp = stack.at(b, p), aq = stack.at(a, q), bq = stack.at(b, q);
  if (!(stack.depth[ap] > 0 && stack.depth[bp] > 0 && stack.depth[aq] > 0 &&
        stack.depth[bq] > 0)) {
    return static_cast<float>(options.lambda_seam_invalid);
  }
  int color = 0;
  for (int c = 0; c < 3; ++c) {
    color += std::abs(stack.rgb[3 * ap + c] - stack.rgb[3 * bp + c]) +
             std::abs(stack.rgb[3 * aq + c] - stack.rgb[3 * bq + c]);
  }
  const float depth = std::abs(stack.log_depth[ap] - stack.log_depth[bp]) +
                      std::abs(stack.log_depth[aq] - stack.log_depth[bq]);
  return static_cast<float>(options.lambda_seam_color) * color / (6.0f * 255.0f) +
         static_cast<float>(options.lambda_seam_depth) * std::min(1.0f, 0.5f * depth * inv_scale);
}

// Edge-aware label upsampling of pixel (x, y): among the labels of the nearby
// solve-resolution pixels, the one whose full-resolution warp best matches
// the colours those pixels show, weighted by distance; where none reaches the
// pixel, the least stretched usable warp; -1 if no warp is usable.
int UpsampleLabel(const FullWarps& warps, const StitchedLayer& out, const Image8& solve_rgb, int x, int y,
                  float front_depth, const StitchOptions& options, std::vector<int>* candidates,
                  std::vector<double>* scores) {
  const int sw = out.solve_label.width(), sh = out.solve_label.height();
  const double scale = static_cast<double>(sw) / warps.width;
  const int r = options.upsample_radius;
  const double inv_two_sigma2 =
      1.0 / (2.0 * options.upsample_sigma_color * options.upsample_sigma_color);
  const double fy = (y + 0.5) * scale - 0.5;
  const int cy0 = static_cast<int>(std::lround(fy));
  const double fx = (x + 0.5) * scale - 0.5;
  const int cx0 = static_cast<int>(std::lround(fx));
  candidates->clear();
  scores->clear();
  for (int dy = -r; dy <= r; ++dy) {
    const int qy = cy0 + dy;
    if (qy < 0 || qy >= sh) continue;
    for (int dx = -r; dx <= r; ++dx) {
      const int qx = WrapColumn(cx0 + dx, sw);
      const int l = out.solve_label.at(qx, qy);
      if (l < 0) continue;
      const warp::WarpedLayer& layer = warps.layer(l);
      int lx, ly;
      if (!warps.Usable(l, x, y, front_depth, &lx, &ly)) continue;
      double diff2 = 0;
      for (int c = 0; c < 3; ++c) {
        const double e = layer.rgb.at(lx, ly, c) - solve_rgb.at(qx, qy, c);
        diff2 += e * e;
      }
      const double ddx = (cx0 + dx) - fx, ddy = qy - fy;
      // Stretched fragments (depth-edge triangles) almost never win.
      const double w = std::exp(-(ddx * ddx + ddy * ddy) * 0.5) *
                       std::exp(-diff2 / 3.0 * inv_two_sigma2) *
                       std::exp(-kUpsampleStretchWeight * layer.stretch.at(lx, ly));
      auto it = std::find(candidates->begin(), candidates->end(), l);
      if (it == candidates->end()) {
        candidates->push_back(l);
        scores->push_back(w + 1e-12);
      } else {
        (*scores)[it - candidates->begin()] += w;
      }
    }
  }
  int best = -1;
  double best_score = -1;
  for (size_t i = 0; i < candidates->size(); ++i) {
    if ((*scores)[i] > best_score) {
      best_score = (*scores)[i];
      best = (*candidates)[i];
    }
  }
  if (best >= 0) return best;
  // No nearby label reaches this pixel: take the least stretched warp.
  float best_stretch = 2.0f;
  for (int l = 0; l < static_cast<int>(warps.full.size()); ++l) {
    const warp::WarpedLayer& layer = warps.layer(l);
    int lx, ly;
    if (!warps.Usable(l, x, y, front_depth, &lx, &ly)) continue;
    if (layer.stretch.at(lx, ly) < best_stretch) {
      best_stretch = layer.stretch.at(lx, ly);
      best = l;
    }
  }
  return best;
}

// The front layer's label at (x, y): `best`, unless a surface nearer than
// best's by more than blend_depth_tolerance has the support of at least
// front_support unstretched warps (itself included); then the warp of the
// nearest such surface. A thin structure that some photos' depth maps miss by
// a pixel or two (a leaflet, a pole) then stays in front where the label's
// photo shows what lies behind it. `scratch` holds (depth, label) pairs.
int NearestSupported(const FullWarps& warps, int best, int x, int y, const StitchOptions& options,
                     std::vector<std::pair<float, int>>* scratch) {
  int lx, ly;
  warps.layer(best).ToCrop(x, y, warps.width, &lx, &ly);
  const double tol = options.blend_depth_tolerance;
  const float limit = static_cast<float>(warps.layer(best).depth_m.at(lx, ly) * (1.0 - tol));
  std::vector<std::pair<float, int>>& found = *scratch;
  found.clear();
  bool nearer = false;  // Most pixels have no candidate nearer than the label's.
  for (int l = 0; l < static_cast<int>(warps.full.size()); ++l) {
    if (!warps.Usable(l, x, y, 0.0f, &lx, &ly)) continue;
    const warp::WarpedLayer& w = warps.layer(l);
    if (w.stretch.at(lx, ly) > kMaxSupportStretch) continue;
    found.emplace_back(w.depth_m.at(lx, ly), l);
    nearer = nearer || found.back().first < limit;
  }
  if (!nearer) return best;
  // Nearest first: the first surface with enough support wins. Sorted, the
  // depths within tol of one are the run around it.
  std::sort(found.begin(), found.end());
  const int n = static_cast<int>(found.size());
  for (int i = 0; i < n && found[i].first < limit; ++i) {
    const float d = found[i].first;
    int lo = i, hi = i;
    while (lo > 0 && std::abs(found[lo - 1].first - d) <= tol * d) --lo;
    while (hi + 1 < n && std::abs(found[hi + 1].first - d) <= tol * d) ++hi;
    if (hi - lo + 1 >= options.front_support) return found[i].second;
  }
  return best;
}

// Writes pixel (x, y) of `out` from label `best` (on the front layer, first
// moved to the nearest supported surface, NearestSupported): its depth and
// colour, or with blend_depth_tolerance > 0 the mean colour and the geometric
// mean depth of the warps that agree with it (BlendMembers).
// `keys` (when not null) gets the BlendKey of the blended warps.
void WritePixel(const FullWarps& warps, int best, int x, int y, float front_depth,
                const StitchOptions& options, std::vector<std::pair<float, int>>* scratch,
                std::vector<std::pair<int, double>>* members, Image<uint64_t>* keys,
                StitchedLayer* out) {
  if (!warps.back && options.front_support > 0 && options.blend_depth_tolerance > 0)
    best = NearestSupported(warps, best, x, y, options, scratch);
  const warp::WarpedLayer& layer = warps.layer(best);
  int lx, ly;
  layer.ToCrop(x, y, warps.width, &lx, &ly);
  out->label.at(x, y) = static_cast<int16_t>(best);
  out->depth_m.at(x, y) = layer.depth_m.at(lx, ly);
  if (!(options.blend_depth_tolerance > 0)) {
    for (int c = 0; c < 3; ++c) out->rgb.at(x, y, c) = layer.rgb.at(lx, ly, c);
    return;
  }
  BlendMembers(warps, best, x, y, front_depth, options, members);
  if (keys) keys->at(x, y) = BlendKey(*members);
  double sum[3] = {0, 0, 0}, weight = 0, dsum = 0;
  for (const auto& [l, w] : *members) {
    const warp::WarpedLayer& other = warps.layer(l);
    int ox, oy;
    other.ToCrop(x, y, warps.width, &ox, &oy);
    for (int c = 0; c < 3; ++c) sum[c] += w * other.rgb.at(ox, oy, c);
    dsum += w * std::log(other.depth_m.at(ox, oy));
    weight += w;
  }
  out->depth_m.at(x, y) = static_cast<float>(std::exp(dsum / weight));
  for (int c = 0; c < 3; ++c)
    out->rgb.at(x, y, c) = static_cast<uint8_t>(std::clamp(std::lround(sum[c] / weight), 0L, 255L));
}

StitchedLayer StitchLayer(bool back, const std::vector<warp::WarpedView>& full,
                          const std::vector<warp::WarpedView>& coarse,
                          const std::vector<ViewGeometry>& views, int pano_width,
                          const StitchedLayer* front, const StitchOptions& options) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("stitch options: " + st.message());
  if (full.size() != coarse.size() || full.size() != views.size() || full.empty()) {
    throw std::invalid_argument("stitch: full, coarse warps and views must be equally many (>0)");
  }
  if (full.size() > 32000) throw std::invalid_argument("stitch: more than 32000 photos");
  const int sw = options.solve_width, sh = options.solve_height;
  const int W = pano_width, H = pano_width / 2;
  const int L = static_cast<int>(full.size());
  const int n = sw * sh;

  // 1. Labels at the solve resolution (an MRF over the coarse warps).
  CoarseStack stack;
  FillStack(coarse, back, sw, sh, &stack);
  // Any-surface depths for the back layer's consistency check.
  CoarseStack front_stack;
  if (back) FillStack(coarse, false, sw, sh, &front_stack);
  GridMrf mrf(sw, sh, L, /*wrap_x=*/true);
  SetDataCosts(back, stack, front_stack, views, front, options, &mrf);
  const float inv_scale = static_cast<float>(1.0 / options.seam_depth_scale);
  auto pairwise = [&](int p, int q, int a, int b) -> float {
    return SeamCost(stack, options, inv_scale, p, q, a, b);
  };
  const std::vector<int> labels = mrf.Solve(pairwise, options.solver);

  StitchedLayer out;
  out.energy = mrf.Energy(labels, pairwise);
  out.solve_label = Image<int16_t>(sw, sh, 1, -1);
  out.solve_depth_m = ImageF(sw, sh, 1, 0.0f);
  Image8 solve_rgb(sw, sh, 3, 0);
  for (int p = 0; p < n; ++p) {
    const int l = labels[p];
    if (l < 0) continue;
    out.solve_label.vector()[p] = static_cast<int16_t>(l);
    out.solve_depth_m.vector()[p] = stack.depth[stack.at(l, p)];
    for (int c = 0; c < 3; ++c) solve_rgb.vector()[3 * p + c] = stack.rgb[3 * stack.at(l, p) + c];
  }

  // 2. The labels upsampled to full resolution, and each pixel's colour and
  // depth from its label's warp (blended with the warps that agree).
  out.rgb = Image8(W, H, 3, 0);
  out.depth_m = ImageF(W, H, 1, 0.0f);
  out.label = Image<int16_t>(W, H, 1, -1);
  const FullWarps warps{back, full, W, options.back_tolerance};
  // Without blending every set is one photo, and no pair of two is joined.
  const bool seam_blend = options.seam_blend_length > 0 && options.blend_depth_tolerance > 0;
  Image<uint64_t> keys;
  if (seam_blend) keys = Image<uint64_t>(W, H, 1, 0);
  base::ParallelFor(0, H, base::ResolveThreads(0), [&](int64_t y64) {
    const int y = static_cast<int>(y64);
    std::vector<int> candidates;
    std::vector<double> scores;
    std::vector<std::pair<float, int>> scratch;
    std::vector<std::pair<int, double>> members;
    for (int x = 0; x < W; ++x) {
      const float front_depth = front ? front->depth_m.at(x, y) : 0.0f;
      const int best = UpsampleLabel(warps, out, solve_rgb, x, y, front_depth, options, &candidates, &scores);
      if (best < 0) continue;
      WritePixel(warps, best, x, y, front_depth, options, &scratch, &members,
                 seam_blend ? &keys : nullptr, &out);
    }
  });

  // 3. Seams between the sets of blended photos evened out (BlendSeams).
  if (seam_blend) BlendSeams(warps, front, options, keys, &out);
  return out;
}

}  // namespace

StitchedLayer StitchFront(const std::vector<warp::WarpedView>& full,
                          const std::vector<warp::WarpedView>& coarse,
                          const std::vector<ViewGeometry>& views, int pano_width,
                          const StitchOptions& options) {
  return StitchLayer(false, full, coarse, views, pano_width, nullptr, options);
}

StitchedLayer StitchBack(const std::vector<warp::WarpedView>& full,
                         const std::vector<warp::WarpedView>& coarse,
                         const std::vector<ViewGeometry>& views, const StitchedLayer& front,
                         const StitchOptions& options) {
  if (front.depth_m.empty() || front.solve_depth_m.empty()) {
    throw std::invalid_argument("stitch: the back stitch needs the stitched front layer");
  }
  return StitchLayer(true, full, coarse, views, front.depth_m.width(), &front, options);
}

}  // namespace casual3d::stitch
