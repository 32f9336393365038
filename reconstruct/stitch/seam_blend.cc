#include "reconstruct/stitch/seam_blend.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "base/parallel_for.h"
#include "reconstruct/stitch/screened_poisson.h"

namespace casual3d::stitch {
namespace {

// The solve stops at a residual of 1% of the right-hand side's: a
// correction a few hundredths of a level from the exact one.
constexpr double kRelativeTolerance = 1e-2;
constexpr int kMaxIterations = 40;
// Jumps are evened out only where the photos that see both sides see a
// smooth surface (their mean step at most this, 8-bit levels, in every
// channel): in texture a jump between photos hides, and the photos' steps
// there, off by their registration, would spread noise.
constexpr double kSmoothStep = 6.0;
// A warp whose own depths at two neighbours differ by more than this sees a
// depth edge between them: its colour step there is the scene's, not a
// seam's, and it gives no target.
constexpr double kWarpEdgeStep = 0.03;

using Members = std::vector<std::pair<int, double>>;

}  // namespace

bool FindSeamWindow(const Image<int16_t>& label, SeamWindow* win) {
  const int W = label.width(), H = label.height();
  std::vector<char> used(W, 0);
  int y0 = H, y1 = -1;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      if (label.at(x, y) < 0) continue;
      used[x] = 1;
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  }
  if (y1 < 0) return false;
  // The longest run of unused columns, cyclically (the first such run).
  int gap = 0, start = 0, run = 0;
  for (int i = 0; i < 2 * W; ++i) {
    const int x = i % W;
    run = used[x] ? 0 : run + 1;
    if (run > gap && run < W) {
      gap = run;
      start = (x + 1) % W;
    }
  }
  win->x0 = gap > 0 ? start : 0;
  win->y0 = y0;
  win->width = W - gap;
  win->height = y1 - y0 + 1;
  win->wrap = gap == 0;
  return true;
}

void BlendSeams(const FullWarps& warps, const StitchedLayer* front, const StitchOptions& options,
                const Image<uint64_t>& keys, StitchedLayer* out) {
  SeamWindow win;
  if (!FindSeamWindow(out->label, &win)) return;
  const int W = out->label.width();
  const int threads = base::ResolveThreads(0);
  const size_t n = static_cast<size_t>(win.width) * win.height;
  auto pano_x = [&](int gx) { return (win.x0 + gx) % W; };
  auto members_at = [&](int gx, int gy, Members* m) {
    const int x = pano_x(gx), y = win.y0 + gy;
    const float front_depth = front ? front->depth_m.at(x, y) : 0.0f;
    BlendMembers(warps, out->label.at(x, y), x, y, front_depth, options, m);
  };

  // Every labelled pixel takes part, screened alike.
  PoissonGrid grid(win.width, win.height, win.wrap);
  const float screen = static_cast<float>(1.0 / std::pow(options.seam_blend_length * W, 2));
  base::ParallelFor(0, win.height, threads, [&](int64_t gy64) {
    const int gy = static_cast<int>(gy64);
    for (int gx = 0; gx < win.width; ++gx) {
      if (out->label.at(pano_x(gx), win.y0 + gy) >= 0) grid.screen[grid.index(gx, gy)] = screen;
    }
  });

  // Each pair's weight, and its target added to b (AddEdgeTarget, three
  // channels per pixel). A pair reaches into the next row: rows of one
  // parity at a time, so that no two threads write the same row.
  std::vector<float> b3(3 * n, 0.0f);
  std::vector<int64_t> with_target(win.height, 0), cut(win.height, 0);
  auto join_row = [&](int gy) {
    Members mp, mq;
    for (int gx = 0; gx < win.width; ++gx) {
      const size_t p = grid.index(gx, gy);
      if (!(grid.screen[p] > 0)) continue;
      mp.clear();
      for (int dir = 0; dir < 2; ++dir) {
        int qx = gx, qy = gy;
        if (dir == 0) {
          qx = grid.Right(gx);
          if (qx < 0) continue;
        } else {
          if (gy + 1 >= win.height) continue;
          qy = gy + 1;
        }
        const size_t q = grid.index(qx, qy);
        if (!(grid.screen[q] > 0)) continue;
        float& weight = dir == 0 ? grid.right[p] : grid.down[p];
        const int xp = pano_x(gx), yp = win.y0 + gy, xq = pano_x(qx), yq = win.y0 + qy;
        if (keys.at(xp, yp) == keys.at(xq, yq)) {
          weight = 1.0f;
          continue;
        }
        if (mp.empty()) members_at(gx, gy, &mp);  // Never empty: the label counts.
        members_at(qx, qy, &mq);
        // The unstretched warps both sets hold (both are in warp order).
        double diff[3] = {0, 0, 0}, sum_w = 0;
        for (size_t i = 0, j = 0; i < mp.size() && j < mq.size();) {
          if (mp[i].first < mq[j].first) { ++i; continue; }
          if (mq[j].first < mp[i].first) { ++j; continue; }
          const warp::WarpedLayer& w = warps.layer(mp[i].first);
          int ax, ay, bx, by;
          w.ToCrop(xp, yp, W, &ax, &ay);
          w.ToCrop(xq, yq, W, &bx, &by);
          const float da = w.depth_m.at(ax, ay), db = w.depth_m.at(bx, by);
          const bool one_surface = w.stretch.at(ax, ay) <= kMaxSupportStretch &&
                                   w.stretch.at(bx, by) <= kMaxSupportStretch &&
                                   std::abs(da - db) <= kWarpEdgeStep * std::min(da, db);
          if (one_surface) {
            const double wt = 0.5 * (mp[i].second + mq[j].second);
            for (int c = 0; c < 3; ++c) diff[c] += wt * (w.rgb.at(bx, by, c) - w.rgb.at(ax, ay, c));
            sum_w += wt;
          }
          ++i;
          ++j;
        }
        if (!(sum_w > 0)) {  // No warp sees both alike: not joined.
          ++cut[gy];
          continue;
        }
        weight = 1.0f;
        bool smooth = true;
        for (int c = 0; c < 3; ++c) smooth = smooth && std::abs(diff[c] / sum_w) <= kSmoothStep;
        if (!smooth) continue;  // Texture or an edge: the blend's own step is kept.
        ++with_target[gy];
        for (int c = 0; c < 3; ++c) {
          const double f_step = out->rgb.at(xq, yq, c) - out->rgb.at(xp, yp, c);
          AddEdgeTarget(3 * p + c, 3 * q + c, 1.0f, static_cast<float>(diff[c] / sum_w - f_step), &b3);
        }
      }
    }
  };
  for (int parity = 0; parity < 2; ++parity) {
    base::ParallelFor(0, (win.height + 1 - parity) / 2, threads,
                      [&](int64_t i) { join_row(static_cast<int>(2 * i + parity)); });
  }
  SeamBlendStats& stats = out->seam_blend;
  stats = SeamBlendStats();
  for (int gy = 0; gy < win.height; ++gy) {
    stats.pairs_with_target += with_target[gy];
    stats.pairs_cut += cut[gy];
  }

  // Per channel: the correction, and the colours moved by it.
  PoissonSolveOptions solve;
  solve.relative_tolerance = kRelativeTolerance;
  solve.max_iterations = kMaxIterations;
  ScreenedPoissonSolver solver(grid, solve);
  std::vector<float> b(n);
  for (int c = 0; c < 3; ++c) {
    for (size_t p = 0; p < n; ++p) b[p] = b3[3 * p + c];
    PoissonSolveReport report;
    const std::vector<float> d = solver.Solve(b, &report);
    stats.iterations = std::max(stats.iterations, report.iterations);
    stats.relative_residual = std::max(stats.relative_residual, report.relative_residual);
    base::ParallelFor(0, win.height, threads, [&](int64_t gy64) {
      const int gy = static_cast<int>(gy64);
      for (int gx = 0; gx < win.width; ++gx) {
        const size_t p = grid.index(gx, gy);
        if (!(grid.screen[p] > 0)) continue;
        uint8_t& v = out->rgb.at(pano_x(gx), win.y0 + gy, c);
        v = static_cast<uint8_t>(std::clamp(std::lround(v + d[p]), 0L, 255L));
      }
    });
  }
}

}  // namespace casual3d::stitch
