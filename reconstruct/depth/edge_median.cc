#include "reconstruct/depth/edge_median.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "base/parallel_for.h"
#include "reconstruct/depth/avx2_clones.h"
#include "reconstruct/depth/color_weights.h"
#include "reconstruct/depth/label_histogram.h"

namespace casual3d::depth {

namespace {

// Filters row y of `labels` into `out`. hist (num_labels zeros, left zeroed)
// and wgt (2r + 1 floats) are the caller's scratch.
CASUAL3D_AVX2_CLONES
void FilterRow(int y, const std::vector<int>& labels, const ColorPlanes& planes, int w, int h, int r,
               const float* spatial, float inv2s2, float* __restrict hist, float* __restrict wgt, int* out) {
  for (int x = 0; x < w; ++x) {
    const size_t c = static_cast<size_t>(y) * w + x;
    const float r0 = planes.r[c], g0 = planes.g[c], b0 = planes.b[c];
    float total = 0.0f;
    LabelHistogram histogram(hist);
    const int u0 = std::max(0, x - r), u1 = std::min(w - 1, x + r), n = u1 - u0 + 1;
    for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v) {
      // The row's weights in a loop that vectorises, then the histogram.
      const size_t row = static_cast<size_t>(v) * w + u0;
      const float* __restrict srow = spatial + (v - y + r) * (2 * r + 1) + (u0 - x + r);
      const float* __restrict pr = planes.r.data() + row;
      const float* __restrict pg = planes.g.data() + row;
      const float* __restrict pb = planes.b.data() + row;
      for (int i = 0; i < n; ++i) {
        wgt[i] = srow[i] * ColorAffinity(pr[i] - r0, pg[i] - g0, pb[i] - b0, inv2s2);
      }
      for (int i = 0; i < n; ++i) total += wgt[i];
      histogram.AddRow(labels.data() + row, wgt, n);
    }
    out[c] = histogram.MedianAndClear(total);
  }
}

}  // namespace

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
  const size_t n = labels.size();
  const ColorPlanes planes = SplitColor(color);

  std::vector<int> out(n);
  base::ParallelFor(0, h, base::ResolveThreads(num_threads), [&](int64_t y) {
    std::vector<float> hist(num_labels, 0.0f), wgt(2 * r + 1);
    FilterRow(static_cast<int>(y), labels, planes, w, h, r, spatial.data(), inv2s2, hist.data(), wgt.data(),
              out.data());
  });
  return out;
}

}  // namespace casual3d::depth
