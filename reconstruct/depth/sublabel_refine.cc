#include "reconstruct/depth/sublabel_refine.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "base/parallel_for.h"

namespace casual3d::depth {

namespace {

void CheckSizes(const CostVolume& volume, size_t labels, const ImageF* color) {
  const size_t np = static_cast<size_t>(volume.width) * volume.height;
  if (labels != np || volume.cost.size() != np * volume.num_labels ||
      (color && (color->width() != volume.width || color->height() != volume.height ||
                 color->channels() != 3)))
    throw std::invalid_argument(
        "sub-label refinement: label map, colour guide and cost volume differ in size");
}

}  // namespace

std::vector<float> FitSubLabel(const CostVolume& volume, const std::vector<int>& labels,
                               const SubLabelOptions& options, int num_threads) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  CheckSizes(volume, labels.size(), nullptr);
  const int w = volume.width, h = volume.height, L = volume.num_labels;
  const size_t np = static_cast<size_t>(w) * h;
  const int threads = base::ResolveThreads(num_threads);

  // Parabola through the cost around the best label next to k.
  std::vector<float> f(np);
  base::ParallelFor(0, h, threads, [&](int64_t y) {
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      const int k = labels[p];
      double kf = k;
      if (options.parabola) {
        const float* c = volume.cost.data() + p * L;
        int kc = k;
        if (k > 0 && c[k - 1] < c[kc]) kc = k - 1;
        if (k + 1 < L && c[k + 1] < c[kc]) kc = k + 1;
        if (kc > 0 && kc + 1 < L && c[kc] <= c[kc - 1] && c[kc] <= c[kc + 1]) {
          const double denom = c[kc - 1] - 2.0 * c[kc] + c[kc + 1];
          if (denom > 1e-6) {
            const double off = std::clamp(0.5 * (c[kc - 1] - c[kc + 1]) / denom, -0.5, 0.5);
            kf = std::clamp(kc + off, k - 1.0, k + 1.0);
          }
        }
      }
      f[p] = static_cast<float>(kf);
    }
  });
  return f;
}

std::vector<float> SmoothSubLabel(const CostVolume& volume, std::vector<float> f,
                                  const ImageF& color, const SubLabelOptions& options,
                                  int num_threads) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  CheckSizes(volume, f.size(), &color);
  const int w = volume.width, h = volume.height;
  const size_t np = static_cast<size_t>(w) * h;
  const int threads = base::ResolveThreads(num_threads);

  // Edge-aware weighted mean, Jacobi passes.
  const int r = options.smooth_radius;
  if (r == 0 || options.smooth_iterations == 0) return f;
  const float inv2s2 = static_cast<float>(1.0 / (2.0 * options.sigma_color * options.sigma_color));
  const float gap = static_cast<float>(options.max_label_gap);
  std::vector<float> conf(np);
  for (size_t p = 0; p < np; ++p)
    conf[p] = volume.photo_weight.data()[p] + static_cast<float>(options.confidence_floor);
  std::vector<float> next(np);
  for (int it = 0; it < options.smooth_iterations; ++it) {
    base::ParallelFor(0, h, threads, [&](int64_t yy) {
      const int y = static_cast<int>(yy);
      for (int x = 0; x < w; ++x) {
        const size_t p = static_cast<size_t>(y) * w + x;
        const float f0 = f[p];
        const float* c0 = &color.at(x, y, 0);
        double sum = 0.0, total = 0.0;
        for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
          for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u) {
            const size_t q = static_cast<size_t>(v) * w + u;
            if (std::abs(f[q] - f0) > gap) continue;
            const float* c = &color.at(u, v, 0);
            const float d2 = (c[0] - c0[0]) * (c[0] - c0[0]) + (c[1] - c0[1]) * (c[1] - c0[1]) +
                             (c[2] - c0[2]) * (c[2] - c0[2]);
            const double wq = std::exp(-d2 * inv2s2) * conf[q];
            sum += wq * f[q];
            total += wq;
          }
        next[p] = total > 0 ? static_cast<float>(sum / total) : f0;
      }
    });
    f.swap(next);
  }
  return f;
}

std::vector<float> RefineSubLabel(const CostVolume& volume, const std::vector<int>& labels,
                                  const ImageF& color, const SubLabelOptions& options,
                                  int num_threads) {
  CheckSizes(volume, labels.size(), &color);
  return SmoothSubLabel(volume, FitSubLabel(volume, labels, options, num_threads), color, options,
                        num_threads);
}

}  // namespace casual3d::depth
