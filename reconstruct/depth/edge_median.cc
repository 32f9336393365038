#include "reconstruct/depth/edge_median.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "reconstruct/depth/fast_exp.h"
#include "reconstruct/depth/parallel.h"

namespace casual3d::depth {

Status EdgeMedianOptions::Check() const {
  if (radius < 0 || radius > 32) return InvalidArgument("edge median radius outside [0, 32]");
  if (!(sigma_spatial > 0 && sigma_spatial <= 64))
    return InvalidArgument("edge median sigma_spatial outside (0, 64]");
  if (!(sigma_color > 0 && sigma_color <= 10))
    return InvalidArgument("edge median sigma_color outside (0, 10]");
  return Status::Ok();
}

std::vector<int> EdgeAwareMedian(const std::vector<int>& labels, int num_labels,
                                 const ImageF& color, const EdgeMedianOptions& options,
                                 int num_threads) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  const int w = color.width(), h = color.height(), r = options.radius;
  if (labels.size() != static_cast<size_t>(w) * h || color.channels() != 3 || num_labels < 1)
    throw std::invalid_argument("edge median: label map and colour guide differ in size");
  if (r == 0) return labels;
  std::vector<float> spatial((2 * r + 1) * (2 * r + 1));
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      spatial[(dy + r) * (2 * r + 1) + dx + r] = static_cast<float>(
          std::exp(-(dx * dx + dy * dy) / (2.0 * options.sigma_spatial * options.sigma_spatial)));
  const float inv2s2 = static_cast<float>(1.0 / (2.0 * options.sigma_color * options.sigma_color));

  std::vector<int> out(labels.size());
  ParallelFor(0, h, ResolveThreads(num_threads), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    std::vector<float> hist(num_labels, 0.0f);
    std::vector<float> wgt(2 * r + 1);
    for (int x = 0; x < w; ++x) {
      const float* c0 = &color.at(x, y, 0);
      float total = 0.0f;
      int kmin = num_labels, kmax = -1;
      const int u0 = std::max(0, x - r), u1 = std::min(w - 1, x + r);
      for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v) {
        // The row's weights in a loop that vectorises, then the histogram.
        const float* srow = spatial.data() + (v - y + r) * (2 * r + 1) + r - x;
        const float* crow = color.row(v);
        for (int u = u0; u <= u1; ++u) {
          const float* c = crow + 3 * u;
          const float d2 = (c[0] - c0[0]) * (c[0] - c0[0]) + (c[1] - c0[1]) * (c[1] - c0[1]) +
                           (c[2] - c0[2]) * (c[2] - c0[2]);
          wgt[u - u0] = srow[u] * ExpNonPositive(-d2 * inv2s2);
        }
        const int* lrow = labels.data() + static_cast<size_t>(v) * w;
        for (int u = u0; u <= u1; ++u) {
          const int k = lrow[u];
          hist[k] += wgt[u - u0];
          total += wgt[u - u0];
          kmin = std::min(kmin, k);
          kmax = std::max(kmax, k);
        }
      }
      float acc = 0.0f;
      int med = kmax;
      for (int k = kmin; k <= kmax; ++k) {
        acc += hist[k];
        if (acc >= 0.5f * total) {
          med = k;
          break;
        }
      }
      std::fill(hist.begin() + kmin, hist.begin() + kmax + 1, 0.0f);
      out[static_cast<size_t>(y) * w + x] = med;
    }
  });
  return out;
}

}  // namespace casual3d::depth
