#include "reconstruct/depth/fullres_refine.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <utility>

#include "base/parallel_for.h"
#include "reconstruct/depth/avx2_clones.h"
#include "reconstruct/depth/color_weights.h"
#include "reconstruct/depth/fast_exp.h"
#include "reconstruct/depth/near_envelope.h"
#include "reconstruct/depth/plane_sweep.h"
#include "reconstruct/depth/zncc_stream.h"

namespace casual3d::depth {

ImageF RefineFullResolution(const ImageF& gray, const PinholeCamera& camera, const ImageF& depth,
                            const std::vector<RefineNeighbor>& neighbors, double inv_step,
                            const FullResRefineOptions& options, int num_threads, FullResRefineStats* stats) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument("full-resolution refinement: " + st.message());
  const int w = gray.width(), h = gray.height();
  if (gray.channels() != 1 || depth.width() != w || depth.height() != h || depth.channels() != 1 ||
      camera.width != w || camera.height != h)
    throw std::invalid_argument("full-resolution refinement: grey image, depth map and camera differ in size");
  if (!(inv_step > 0)) throw std::invalid_argument("full-resolution refinement: inv_step must be > 0");
  for (const RefineNeighbor& nb : neighbors)
    if (!nb.gray || nb.gray->channels() != 1 || nb.gray->width() != nb.camera.width ||
        nb.gray->height() != nb.camera.height)
      throw std::invalid_argument("full-resolution refinement: a neighbour's image and camera differ in size");
  if (stats) *stats = FullResRefineStats();
  if (!options.enabled || neighbors.empty()) return depth;

  const size_t n = static_cast<size_t>(w) * h;
  const int r = options.window_radius;
  const int steps = options.steps;
  const float eps = static_cast<float>(options.ncc_epsilon);
  const ReferenceWindows windows = ComputeReferenceWindows(gray.data(), w, h, r, eps);
  std::vector<float> inv0(n);
  for (size_t i = 0; i < n; ++i) inv0[i] = 1.0f / depth.data()[i];

  struct Warp {
    const ImageF* gray;
    PlaneHomography hom;
  };
  std::vector<Warp> warps;
  for (const RefineNeighbor& nb : neighbors) warps.push_back({nb.gray, ComputePlaneHomography(camera, nb.camera)});
  const int num_nb = static_cast<int>(warps.size());
  auto offset = [&](int j) {
    return options.search_labels * (2.0 * j / (steps - 1) - 1.0);
  };

  // Costs of every offset, plane-major.
  std::vector<float> costs(static_cast<size_t>(steps) * n);
  // Per thread: a ZNCC stream and a row of shifted inverse depths, made on
  // its first offset.
  struct Scratch {
    std::optional<ZnccStream> stream;
    std::vector<float> inv_row;
  };
  const int threads = std::max(1, std::min(num_threads, steps));
  std::vector<Scratch> scratch(threads);
  base::ParallelFor(0, steps, threads, [&](int64_t step, int thread) {
    Scratch& own = scratch[thread];
    if (!own.stream) {
      own.stream.emplace(w, h, r, num_nb, options.best_k,
                         static_cast<float>(options.occlusion_truncation), eps, gray.data(),
                         &windows);
      own.inv_row.resize(w);
    }
    std::vector<float>& inv_row = own.inv_row;
    const int j = static_cast<int>(step);
    const float shift = static_cast<float>(offset(j) * inv_step);
    float* plane = costs.data() + static_cast<size_t>(j) * n;
    int last_row = -1;
    own.stream->Run(
        [&](int k, int y, float* values, float* invalid) {
          if (y != last_row) {
            const float* src = inv0.data() + static_cast<size_t>(y) * w;
            for (int x = 0; x < w; ++x) inv_row[x] = std::max(0.0f, src[x] + shift);
            last_row = y;
          }
          // The plane part at inverse depth 0; each pixel adds its own inv * b.
          const PlaneHomography& hm = warps[k].hom;
          sweep::WarpRowPerPixel(warps[k].gray->data(), warps[k].gray->width(),
                                 warps[k].gray->height(), hm.Row(y, 0.0f), inv_row.data(), hm.b,
                                 w, values, invalid);
        },
        [&](int y) { return plane + static_cast<size_t>(y) * w; });
  });

  // Per pixel: the offset of least cost, a parabola through it and its two
  // neighbours; interior minima of textured pixels move the depth.
  const float tsig2 = static_cast<float>(options.texture_sigma * options.texture_sigma);
  const float step_labels = static_cast<float>(2.0 * options.search_labels / (steps - 1));
  ImageF out = depth;
  long long refined = 0, textured = 0;
  for (size_t p = 0; p < n; ++p) {
    const float var = windows.variance[p];
    if (var / (var + tsig2) < options.min_texture) continue;
    ++textured;
    int best = 0;
    for (int j = 1; j < steps; ++j)
      if (costs[static_cast<size_t>(j) * n + p] < costs[static_cast<size_t>(best) * n + p]) best = j;
    if (best == 0 || best == steps - 1) continue;
    const float c0 = costs[static_cast<size_t>(best - 1) * n + p];
    const float c1 = costs[static_cast<size_t>(best) * n + p];
    const float c2 = costs[static_cast<size_t>(best + 1) * n + p];
    if (c1 >= 1.0f) continue;  // No neighbour sees the pixel.
    const float den = c0 - 2.0f * c1 + c2;
    float frac = den > 1e-9f ? 0.5f * (c0 - c2) / den : 0.0f;
    frac = std::min(0.5f, std::max(-0.5f, frac));
    const double labels = offset(best) + frac * step_labels;
    const double inv = inv0[p] + labels * inv_step;
    if (!(inv > 0)) continue;
    out.data()[p] = static_cast<float>(1.0 / inv);
    ++refined;
  }
  if (stats) {
    stats->refined = refined;
    stats->textured = textured;
  }
  return out;
}

}  // namespace casual3d::depth

namespace casual3d::depth {


namespace {

// The relabelling window's m8 samples (a multiple of 8; padding has zero
// weight) against one neighbour J at inverse depth inv_d: positions (sx, sy)
// projected through H, each sample weighted by wgt where J sees it (0
// outside it or behind it: NaN fails every comparison). False when J does
// not see the centre sample; otherwise sums = {sum w, sum w j, sum w j^2,
// sum w i j} over the samples (i: ival, the reference's grey values; j: J's,
// bilinear). us, vs, wk, jv: scratch of m8 floats.
CASUAL3D_AVX2_CLONES
bool WindowSums(const PlaneHomography& H, const ImageF& J, int m8, int centre, const float* __restrict sx,
                const float* __restrict sy, const float* __restrict wgt, const float* __restrict ival,
                float inv_d, float* __restrict us, float* __restrict vs, float* __restrict wk,
                float* __restrict jv, double sums[4]) {
  H.ProjectMany(sx, sy, m8, inv_d, us, vs);
  const float umax = J.width() - 1.001f, vmax = J.height() - 1.001f;
  for (int i = 0; i < m8; ++i) {
    const bool in = (us[i] >= 0.0f) & (vs[i] >= 0.0f) & (us[i] <= umax) & (vs[i] <= vmax);
    us[i] = in ? us[i] : 0.0f;
    vs[i] = in ? vs[i] : 0.0f;
    wk[i] = in ? wgt[i] : 0.0f;
  }
  if (!(wk[centre] > 0.0f)) return false;
  const float* jd = J.data();
  const size_t jw = J.width();
  for (int i = 0; i < m8; ++i) {
    const int iu = static_cast<int>(us[i]), iv = static_cast<int>(vs[i]);
    const float fu = us[i] - iu, fv = vs[i] - iv;
    const float* row0 = jd + static_cast<size_t>(iv) * jw + iu;
    const float* row1 = row0 + jw;
    jv[i] = (1 - fv) * (row0[0] + fu * (row0[1] - row0[0])) + fv * (row1[0] + fu * (row1[1] - row1[0]));
  }
  // Eight partial sums at a time.
  float a_w[8] = {}, a_j[8] = {}, a_jj[8] = {}, a_ij[8] = {};
  for (int i = 0; i < m8; i += 8)
    for (int l = 0; l < 8; ++l) {
      const float wq = wk[i + l], jq = jv[i + l];
      a_w[l] += wq;
      a_j[l] += wq * jq;
      a_jj[l] += wq * jq * jq;
      a_ij[l] += wq * jq * ival[i + l];
    }
  sums[0] = sums[1] = sums[2] = sums[3] = 0;
  for (int l = 0; l < 8; ++l) {
    sums[0] += a_w[l];
    sums[1] += a_j[l];
    sums[2] += a_jj[l];
    sums[3] += a_ij[l];
  }
  return true;
}

// Throws std::invalid_argument unless the images, depth map, camera and
// neighbours agree in size and channels and inv_step > 0.
void CheckRelabelInputs(const ImageF& color, const ImageF& gray, const PinholeCamera& camera,
                        const ImageF& depth, const std::vector<RefineNeighbor>& neighbors, double inv_step) {
  const int w = gray.width(), h = gray.height();
  if (color.width() != w || color.height() != h || color.channels() != 3 || depth.width() != w ||
      depth.height() != h || camera.width != w || camera.height != h)
    throw std::invalid_argument("boundary relabelling: images, depth map and camera differ in size");
  if (gray.channels() != 1 || depth.channels() != 1)
    throw std::invalid_argument("boundary relabelling: grey image and depth map need one channel");
  if (!(inv_step > 0)) throw std::invalid_argument("boundary relabelling: inv_step must be > 0");
  for (const RefineNeighbor& nb : neighbors)
    if (!nb.gray || nb.gray->channels() != 1 || nb.gray->width() != nb.camera.width ||
        nb.gray->height() != nb.camera.height)
      throw std::invalid_argument("boundary relabelling: a neighbour's image and camera differ in size");
}

// The band: pixels within `radius` (a window of `diameter`) of a depth edge,
// two 4-neighbours whose inverse depths differ by more than `jump` (the
// upsampling's weighted median leaves steps there). A slope spans as much
// over the band window but has no such step, and is left alone.
std::vector<uint8_t> EdgeBand(const ImageF& inv_image, float jump, int diameter) {
  const int w = inv_image.width(), h = inv_image.height();
  const size_t n = static_cast<size_t>(w) * h;
  std::vector<uint8_t> near_edge(n, 0);
  ImageF neg_edge(w, h, 1, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      const float a = inv_image.data()[p];
      if ((x + 1 < w && std::abs(a - inv_image.data()[p + 1]) > jump) ||
          (y + 1 < h && std::abs(a - inv_image.data()[p + w]) > jump))
        neg_edge.data()[p] = -1.0f;
    }
  const ImageF band = MinFilter(neg_edge, diameter);
  for (size_t i = 0; i < n; ++i) near_edge[i] = band.data()[i] < -0.5f;
  return near_edge;
}

// What every pixel's relabelling reads.
struct RelabelContext {
  const ImageF& color;
  const ImageF& gray;
  const std::vector<RefineNeighbor>& neighbors;
  const std::vector<PlaneHomography>& homs;  // The first K neighbours'.
  const BoundaryRelabelOptions& options;
  const float* inv;      // Inverse depth.
  const float* inv_min;  // Its minimum over the band window.
  float same;            // One label of inverse depth.
};

// Relabels the pixels of rows, one at a time, with its own scratch buffers.
class PixelRelabeller {
 public:
  explicit PixelRelabeller(const RelabelContext& c) : c_(c) {
    const BoundaryRelabelOptions& o = c.options;
    K_ = static_cast<int>(c.homs.size());
    r_ = o.window_radius;
    step_ = o.window_step;
    // Window samples at multiples of step within r of the centre (the centre
    // included): `side` per row and column.
    reach_ = (r_ / step_) * step_;
    const int side = 2 * (r_ / step_) + 1;
    inv2s2_ = static_cast<float>(1.0 / (2.0 * o.sigma_color * o.sigma_color));
    eps_ = static_cast<float>(o.ncc_epsilon);
    best_k_ = std::min(o.best_k, K_);
    trunc_ = static_cast<float>(o.occlusion_truncation);
    tex_s2_ = o.texture_sigma * o.texture_sigma;
    // The window's samples, padded to a multiple of 8 with zero weights:
    // the cost's loops run on eight samples at a time.
    padded_ = (side * side + 7) & ~7;
    wgt_.assign(padded_, 0.0f);
    ival_.assign(padded_, 0.0f);
    sx_.assign(padded_, 0.0f);
    sy_.assign(padded_, 0.0f);
    us_.resize(padded_);
    vs_.resize(padded_);
    wk_.resize(padded_);
    jv_.resize(padded_);
    costs_.resize(K_);
    // Colours of the samples whose colour weights are computed together.
    const int band_side = 2 * o.radius / kBandStep + 1;  // Samples along a side of the band window, at most.
    const size_t max_samples = std::max<size_t>(padded_, static_cast<size_t>(band_side) * band_side);
    pr_.resize(max_samples);
    pg_.resize(max_samples);
    pb_.resize(max_samples);
    pw_.resize(max_samples);
    pinv_.resize(max_samples);
  }

  // Whether band pixel (x, y) takes a farther surface: a candidate that
  // matches the neighbours better by min_gain; its inverse depth in *inv.
  bool Relabel(int x, int y, float* inv) {
    const int w = c_.gray.width();
    const size_t p = static_cast<size_t>(y) * w + x;
    // Only a farther surface at least a label away counts: most pixels of
    // a band are already on that side.
    const float cur = c_.inv[p];
    if (cur - c_.inv_min[p] < c_.same) return false;
    c0_ = &c_.color.at(x, y, 0);
    if (!ReferenceWindow(x, y)) return false;
    const float base = Cost(cur);
    // No candidate can beat a cost below min_gain by min_gain (costs are
    // >= 0): skip the candidates.
    if (base < c_.options.min_gain) return false;
    float cands[2];
    int num_cands = 0;
    if (FartherMedian(x, y, cur, &cands[0])) ++num_cands;
    cands[num_cands++] = c_.inv_min[p];
    float best_inv = cur, best_cost = base;
    for (int ci = 0; ci < num_cands; ++ci) {
      const float cand = cands[ci];
      if (std::abs(cand - cur) < c_.same) continue;
      if (ci > 0 && std::abs(cand - cands[0]) < 0.5f * c_.same) continue;
      const float cost = Cost(cand);
      if (cost < best_cost) {
        best_cost = cost;
        best_inv = cand;
      }
    }
    if (!(best_inv != cur && base - best_cost >= c_.options.min_gain && best_inv > 0)) return false;
    *inv = best_inv;
    return true;
  }

 private:
  static constexpr int kBandStep = 4;  // The band window: every 4th pixel.

  void GatherColor(int i, int u, int v) {
    const float* c = &c_.color.at(u, v, 0);
    pr_[i] = c[0];
    pg_[i] = c[1];
    pb_[i] = c[2];
  }

  // The colour-weighted window of the reference: pixel (u, v) weighs
  // exp(-|c_uv - c_xy|^2 / (2 sigma_color^2)). False if it is too
  // textureless to judge (below min_texture).
  bool ReferenceWindow(int x, int y) {
    const int w = c_.gray.width(), h = c_.gray.height();
    int m = 0;
    centre_ = 0;
    for (int dv = -reach_; dv <= reach_; dv += step_) {
      const int v = y + dv;
      if (v < 0 || v >= h) continue;
      for (int du = -reach_; du <= reach_; du += step_) {
        const int u = x + du;
        if (u < 0 || u >= w) continue;
        if (du == 0 && dv == 0) centre_ = m;
        GatherColor(m, u, v);
        ival_[m] = c_.gray.at(u, v);
        sx_[m] = static_cast<float>(u);
        sy_[m] = static_cast<float>(v);
        ++m;
      }
    }
    ColorWeights(pr_.data(), pg_.data(), pb_.data(), m, c0_, inv2s2_, wgt_.data());
    double si = 0, sii = 0;
    sw_ = 0;
    for (int i = 0; i < m; ++i) {
      sw_ += wgt_[i];
      si += wgt_[i] * ival_[i];
      sii += wgt_[i] * ival_[i] * ival_[i];
    }
    for (int i = m; i < padded_; ++i) wgt_[i] = ival_[i] = sx_[i] = sy_[i] = 0.0f;
    m8_ = (m + 7) & ~7;
    mi_ = si / sw_;
    vi_ = std::max(0.0, sii / sw_ - mi_ * mi_);
    return vi_ / (vi_ + tex_s2_) >= c_.options.min_texture;
  }

  // The matching cost of inverse depth inv_c: the mean of the best_k
  // neighbours' 1 - weighted ZNCC, each truncated at the best plus
  // occlusion_truncation; 1 if no neighbour sees the window.
  float Cost(float inv_c) {
    int valid = 0;
    for (int k = 0; k < K_; ++k) {
      double sums[4];
      if (!WindowSums(c_.homs[k], *c_.neighbors[k].gray, m8_, centre_, sx_.data(), sy_.data(), wgt_.data(),
                      ival_.data(), inv_c, us_.data(), vs_.data(), wk_.data(), jv_.data(), sums))
        continue;
      const double swk = sums[0], sj = sums[1], sjj = sums[2], sij = sums[3];
      if (swk < 0.5 * sw_) continue;
      // Weighted ZNCC over the pixels the neighbour sees.
      const double mj = sj / swk;
      const double vj = std::max(0.0, sjj / swk - mj * mj);
      const double cov = sij / swk - mi_ * mj;
      const double z = cov / std::sqrt((vi_ + eps_) * (vj + eps_));
      costs_[valid++] = static_cast<float>(std::min(1.0, std::max(0.0, 1.0 - z)));
    }
    if (valid == 0) return 1.0f;
    std::sort(costs_.begin(), costs_.begin() + valid);
    const int kk = std::min(best_k_, valid);
    float s = 0;
    for (int i = 0; i < kk; ++i) s += std::min(costs_[i], costs_[0] + trunc_);
    return s / kk;
  }

  // The colour-weighted median of the farther inverse depths in the band
  // window (the surface of the pixel's own colour beyond the edge); false if
  // they weigh too little.
  bool FartherMedian(int x, int y, float cur, float* median) {
    const int w = c_.gray.width(), h = c_.gray.height();
    const int R = c_.options.radius;
    int ns = 0;
    for (int v = std::max(0, y - R); v <= std::min(h - 1, y + R); v += kBandStep)
      for (int u = std::max(0, x - R); u <= std::min(w - 1, x + R); u += kBandStep) {
        const size_t q = static_cast<size_t>(v) * w + u;
        if (cur - c_.inv[q] < c_.same) continue;
        GatherColor(ns, u, v);
        pinv_[ns++] = c_.inv[q];
      }
    ColorWeights(pr_.data(), pg_.data(), pb_.data(), ns, c0_, inv2s2_, pw_.data());
    samples_.clear();
    double total = 0;
    for (int i = 0; i < ns; ++i) {
      samples_.push_back({pinv_[i], pw_[i]});
      total += pw_[i];
    }
    if (!(total > 0.5)) return false;
    std::sort(samples_.begin(), samples_.end());
    double acc = 0;
    for (const auto& sm : samples_) {
      acc += sm.second;
      if (acc >= 0.5 * total) {
        *median = sm.first;
        return true;
      }
    }
    return false;
  }

  const RelabelContext& c_;
  int K_, r_, step_, reach_, best_k_, padded_;
  float inv2s2_, eps_, trunc_;
  double tex_s2_;
  std::vector<float> wgt_, ival_, sx_, sy_, us_, vs_, wk_, jv_, costs_;
  std::vector<float> pr_, pg_, pb_, pw_, pinv_;
  std::vector<std::pair<float, float>> samples_;
  // The current pixel's reference window.
  const float* c0_ = nullptr;
  int centre_ = 0, m8_ = 0;
  double sw_ = 0, mi_ = 0, vi_ = 0;
};

}  // namespace

ImageF RelabelBoundaries(const ImageF& color, const ImageF& gray, const PinholeCamera& camera,
                         const ImageF& depth, const std::vector<RefineNeighbor>& neighbors, double inv_step,
                         const BoundaryRelabelOptions& options, int num_threads, long long* changed) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument("boundary relabelling: " + st.message());
  CheckRelabelInputs(color, gray, camera, depth, neighbors, inv_step);
  const int w = gray.width(), h = gray.height();
  if (changed) *changed = 0;
  if (!options.enabled || neighbors.empty()) return depth;
  const size_t n = static_cast<size_t>(w) * h;
  // Inverse depth and its minimum over the band window.
  ImageF inv_image(w, h, 1);
  for (size_t i = 0; i < n; ++i) inv_image.data()[i] = 1.0f / depth.data()[i];
  const int diameter = 2 * options.radius + 1;
  const ImageF min_image = MinFilter(inv_image, diameter);
  const float jump = static_cast<float>(options.min_jump_labels * inv_step);
  const std::vector<uint8_t> near_edge = EdgeBand(inv_image, jump, diameter);

  // The first max_neighbors neighbours.
  const int K = std::min(static_cast<int>(neighbors.size()), options.max_neighbors);
  std::vector<PlaneHomography> homs;
  for (int k = 0; k < K; ++k) homs.push_back(ComputePlaneHomography(camera, neighbors[k].camera));
  const RelabelContext context{color,           gray,           neighbors, homs, options, inv_image.data(),
                               min_image.data(), static_cast<float>(inv_step)};
  ImageF out = depth;
  std::vector<long long> changed_rows(h, 0);
  base::ParallelFor(0, h, std::max(1, num_threads), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    PixelRelabeller relabeller(context);
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      if (!near_edge[p]) continue;
      float best_inv;
      if (relabeller.Relabel(x, y, &best_inv)) {
        out.data()[p] = 1.0f / best_inv;
        ++changed_rows[y];
      }
    }
  });
  if (changed)
    for (long long c : changed_rows) *changed += c;
  return out;
}

}  // namespace casual3d::depth
