#include "reconstruct/depth/continuous_refine.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "reconstruct/depth/parallel.h"
#include "reconstruct/depth/sweep_kernels.h"

namespace casual3d::depth {
namespace {

// A neighbour's image and plane-induced homography, as in the sweep.
struct Neighbor {
  const ImageF* gray = nullptr;
  PlaneHomography h;
};

constexpr int kMaxWindow = 31;  // 2 * 15 + 1: the sweep's largest window.

// Everything one pixel's evaluations share.
struct Context {
  const ImageF* ref_gray = nullptr;
  const std::vector<Neighbor>* neighbors = nullptr;
  const float* mean_i = nullptr;
  const float* inv_std_i = nullptr;
  int r = 3;
  float epsilon = 0.0f;
};

// The sweep's cost (plane_sweep.h) of pixel (x, y) against neighbour `nb` on
// the fronto-parallel plane of inverse depth `inv_d`: 1 - ZNCC over the
// window clipped to the reference image, window pixels the neighbour does not
// see counted as black, kInvalidCost when it does not see the centre.
float WindowCost(const Context& ctx, const Neighbor& nb, int x, int y, float inv_d) {
  const int w = ctx.ref_gray->width(), h = ctx.ref_gray->height();
  const int x0 = std::max(0, x - ctx.r), x1 = std::min(w - 1, x + ctx.r);
  const int y0 = std::max(0, y - ctx.r), y1 = std::min(h - 1, y + ctx.r);
  const int ww = x1 - x0 + 1;
  float values[kMaxWindow + 4], invalid[kMaxWindow + 4];
  float sj = 0.0f, sjj = 0.0f, sij = 0.0f;
  bool centre_seen = false;
  const float u0 = static_cast<float>(x0) + 0.5f;
  for (int v = y0; v <= y1; ++v) {
    sweep::HomographyRow row;
    const float vc = static_cast<float>(v) + 0.5f;
    for (int c = 0; c < 3; ++c) {
      row.p0[c] = nb.h.a[c][0] * u0 + nb.h.a[c][1] * vc + nb.h.a[c][2] + nb.h.b[c] * inv_d;
      row.step[c] = nb.h.a[c][0];
    }
    sweep::WarpRow(nb.gray->data(), nb.gray->width(), nb.gray->height(), row, ww, values, invalid);
    if (v == y) centre_seen = invalid[x - x0] == 0.0f;
    const float* irow = ctx.ref_gray->data() + static_cast<size_t>(v) * w + x0;
    for (int u = 0; u < ww; ++u) {
      const float j = values[u];
      sj += j;
      sjj += j * j;
      sij += j * irow[u];
    }
  }
  if (!centre_seen) return sweep::kInvalidCost;
  const float ic = 1.0f / static_cast<float>(ww * (y1 - y0 + 1));
  const size_t p = static_cast<size_t>(y) * w + x;
  const float mj = sj * ic;
  const float var_j = std::max(0.0f, sjj * ic - mj * mj);
  const float cov = sij * ic - ctx.mean_i[p] * mj;
  const float ncc = cov * ctx.inv_std_i[p] / std::sqrt(var_j + ctx.epsilon);
  return std::min(1.0f, std::max(0.0f, 1.0f - ncc));
}

}  // namespace

std::vector<float> RefineContinuous(const DenseView& ref, const std::vector<const DenseView*>& neighbors,
                                    const CostVolume& volume, const std::vector<int>& labels,
                                    const std::vector<float>& start, const SweepOptions& sweep,
                                    const ContinuousRefineOptions& options, int num_threads) {
  for (const Status& s : {options.Check(), sweep.Check()})
    if (!s.ok()) throw std::invalid_argument("continuous refinement: " + s.message());
  const int w = ref.gray.width(), h = ref.gray.height();
  const size_t np = static_cast<size_t>(w) * h;
  if (volume.width != w || volume.height != h || labels.size() != np || start.size() != np ||
      volume.photo_weight.width() != w || volume.photo_weight.height() != h)
    throw std::invalid_argument("continuous refinement: label maps, cost volume and view differ in size");
  if (!options.enabled || neighbors.empty()) return start;
  const int r = sweep.window_radius;
  const int L = volume.num_labels;

  // Reference window statistics, as the sweep computes them.
  std::vector<float> mean_i(np), inv_std_i(np);
  const float eps = static_cast<float>(sweep.ncc_epsilon);
  const float* gi = ref.gray.data();
  ParallelFor(0, h, ResolveThreads(num_threads), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    for (int x = 0; x < w; ++x) {
      double s = 0.0, ss = 0.0;
      int count = 0;
      for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
        for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u) {
          const double g = gi[static_cast<size_t>(v) * w + u];
          s += g;
          ss += g * g;
          ++count;
        }
      const double m = s / count;
      const double var = std::max(0.0, ss / count - m * m);
      mean_i[static_cast<size_t>(y) * w + x] = static_cast<float>(m);
      inv_std_i[static_cast<size_t>(y) * w + x] = static_cast<float>(1.0 / std::sqrt(var + eps));
    }
  });

  std::vector<Neighbor> nbs(neighbors.size());
  for (size_t j = 0; j < neighbors.size(); ++j) {
    nbs[j].gray = &neighbors[j]->gray;
    nbs[j].h = ComputePlaneHomography(ref.camera, neighbors[j]->camera);
  }
  Context ctx;
  ctx.ref_gray = &ref.gray;
  ctx.neighbors = &nbs;
  ctx.mean_i = mean_i.data();
  ctx.inv_std_i = inv_std_i.data();
  ctx.r = r;
  ctx.epsilon = eps;

  const int best_k = std::min<int>(sweep.best_k, static_cast<int>(nbs.size()));
  const double step = options.coarse_step;
  const int half_steps = static_cast<int>(std::floor(options.search_labels / step + 1e-9));
  auto inv_depth = [&](double label) { return static_cast<float>(volume.InvDepthOfLabel(label)); };

  std::vector<float> out(start);
  ParallelFor(0, h, ResolveThreads(num_threads), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    std::vector<int> chosen;
    std::vector<std::pair<float, int>> ranked;
    std::vector<double> grid;
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      if (volume.photo_weight.data()[p] < options.min_weight) continue;
      const int k = std::clamp(labels[p], 0, L - 1);
      // The pixel's best neighbours at the MRF label (the sweep's best-k rule).
      ranked.clear();
      for (size_t j = 0; j < nbs.size(); ++j) {
        const float c = WindowCost(ctx, nbs[j], x, y, inv_depth(k));
        if (c < sweep::kInvalidCost) ranked.emplace_back(c, static_cast<int>(j));
      }
      if (ranked.empty()) continue;
      std::sort(ranked.begin(), ranked.end());
      chosen.clear();
      double cost_k = 0.0;
      for (int q = 0; q < std::min<int>(best_k, static_cast<int>(ranked.size())); ++q) {
        chosen.push_back(ranked[q].second);
        cost_k += ranked[q].first;
      }
      cost_k /= static_cast<double>(chosen.size());
      // Mean cost of the chosen neighbours at a fractional label (a neighbour
      // that stops seeing the pixel counts as the worst cost, 1).
      auto cost_at = [&](double label) {
        double s = 0.0;
        for (int j : chosen) s += std::min(1.0f, WindowCost(ctx, nbs[j], x, y, inv_depth(label)));
        return s / static_cast<double>(chosen.size());
      };
      const double f0 = start[p];
      // Grid costs, index s + half_steps (2.0 = outside the label range).
      grid.assign(2 * half_steps + 1, 2.0);
      grid[half_steps] = cost_k;
      int best_s = 0;
      for (int s = -half_steps; s <= half_steps; ++s) {
        const double label = k + s * step;
        if (s == 0 || label < 0 || label > L - 1) continue;
        grid[s + half_steps] = cost_at(label);
        if (grid[s + half_steps] < grid[best_s + half_steps]) best_s = s;
      }
      // Halve the step around the best grid point, then a parabola through
      // the best of the three and its two neighbours at the half step (the
      // outer one is a grid point already evaluated).
      const double hstep = 0.5 * step;
      const double best = k + best_s * step, best_cost = grid[best_s + half_steps];
      const double c_lo = best - hstep >= 0 ? cost_at(best - hstep) : 2.0;
      const double c_hi = best + hstep <= L - 1 ? cost_at(best + hstep) : 2.0;
      auto grid_cost = [&](int s) { return s < -half_steps || s > half_steps ? 2.0 : grid[s + half_steps]; };
      double centre = best, cm = c_lo, c0 = best_cost, cp = c_hi;
      if (c_lo < best_cost && c_lo <= c_hi) {
        centre = best - hstep, cm = grid_cost(best_s - 1), c0 = c_lo, cp = best_cost;
      } else if (c_hi < best_cost) {
        centre = best + hstep, cm = best_cost, c0 = c_hi, cp = grid_cost(best_s + 1);
      }
      double refined = centre;
      if (cm < 2.0 && cp < 2.0) {
        const double denom = cm - 2.0 * c0 + cp;
        if (denom > 1e-7) refined = centre + std::clamp(0.5 * (cm - cp) / denom, -0.5, 0.5) * hstep;
      }
      const double refined_cost = c0;
      refined = std::clamp(refined, k - options.search_labels, k + options.search_labels);
      if (refined_cost <= cost_at(f0)) out[p] = static_cast<float>(std::clamp(refined, 0.0, L - 1.0));
    }
  });
  return out;
}

}  // namespace casual3d::depth
