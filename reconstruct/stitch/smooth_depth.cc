#include "reconstruct/stitch/smooth_depth.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "base/parallel_for.h"
#include "format/equirect.h"

namespace casual3d::stitch {

void SmoothDepthAlongSurfaces(ImageF* depth_m, const DepthSmoothOptions& options,
                              int num_threads) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("depth smoothing options: " + st.message());
  if (options.radius == 0 || depth_m->empty()) return;
  const int W = depth_m->width(), H = depth_m->height(), r = options.radius;
  const float tol = static_cast<float>(options.tolerance);
  // Log-depth of every pixel, 0 where there is none (valid marks which).
  std::vector<float> log_depth(static_cast<size_t>(W) * H, 0.0f);
  std::vector<uint8_t> valid(log_depth.size(), 0);
  for (size_t i = 0; i < log_depth.size(); ++i) {
    const float d = depth_m->vector()[i];
    if (std::isfinite(d) && d > 0) {
      valid[i] = 1;
      log_depth[i] = std::log(d);
    }
  }
  // |d' - d| <= tol d, in log space: log(1 - tol) <= l' - l <= log(1 + tol).
  const float lo = std::log(1.0f - tol), hi = std::log(1.0f + tol);
  // Column of x + dx for dx in [-r, r] at index x + dx + r (wrapping).
  std::vector<int> column(static_cast<size_t>(W) + 2 * r);
  for (int k = 0; k < W + 2 * r; ++k) column[k] = WrapColumn(k - r, W);
  std::vector<float> next = log_depth;
  for (int pass = 0; pass < options.iterations; ++pass) {
    base::ParallelFor(0, H, base::ResolveThreads(num_threads), [&](int64_t y64) {
      const int y = static_cast<int>(y64);
      const int y0 = std::max(0, y - r), y1 = std::min(H - 1, y + r);
      for (int x = 0; x < W; ++x) {
        const size_t i = static_cast<size_t>(y) * W + x;
        if (!valid[i]) continue;
        const float l0 = log_depth[i];
        double sum = 0;
        int n = 0;
        for (int yy = y0; yy <= y1; ++yy) {
          const size_t row = static_cast<size_t>(yy) * W;
          for (int k = x; k <= x + 2 * r; ++k) {
            const size_t j = row + column[k];
            if (!valid[j]) continue;
            const float e = log_depth[j] - l0;
            if (e < lo || e > hi) continue;
            sum += log_depth[j];
            ++n;
          }
        }
        next[i] = static_cast<float>(sum / n);
      }
    });
    log_depth.swap(next);
  }
  for (size_t i = 0; i < log_depth.size(); ++i)
    if (valid[i]) depth_m->vector()[i] = std::exp(log_depth[i]);
}

}  // namespace casual3d::stitch
