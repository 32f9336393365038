#include "reconstruct/depth/median_prune.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/parallel_for.h"
#include "reconstruct/depth/avx2_clones.h"
#include "reconstruct/depth/color_weights.h"
#include "reconstruct/depth/label_histogram.h"

namespace casual3d::depth {
namespace {

// True when `depth` agrees with the median label `median_label`.
bool WithinBand(double depth, double label, double median_label, const LabelGrid& grid,
                const MedianPruneOptions& o) {
  if (std::abs(label - median_label) <= 1.0) return true;
  const double ratio = depth / grid.DepthOf(median_label);
  return ratio >= o.band_low && ratio <= o.band_high;
}

}  // namespace

ImageF MedianPrune(const ImageF& depth, const LabelGrid& grid, const MedianPruneOptions& options,
                   int num_threads) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  const int w = depth.width(), h = depth.height(), r = options.small_radius;
  ImageF out(w, h, 1, 0.0f);
  base::ParallelFor(0, h, base::ResolveThreads(num_threads), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    std::vector<float> labels;
    labels.reserve((2 * r + 1) * (2 * r + 1));
    for (int x = 0; x < w; ++x) {
      const float d = depth.at(x, y);
      if (!(d > 0)) continue;
      labels.clear();
      int window = 0;
      for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v) {
        for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u) {
          ++window;
          const float e = depth.at(u, v);
          if (e > 0) labels.push_back(static_cast<float>(grid.LabelOf(e)));
        }
      }
      // The pixel itself is not evidence for its own validity.
      if (static_cast<double>(labels.size() - 1) < options.small_min_valid * (window - 1)) continue;
      auto mid = labels.begin() + labels.size() / 2;
      std::nth_element(labels.begin(), mid, labels.end());
      if (WithinBand(d, grid.LabelOf(d), *mid, grid, options)) out.at(x, y) = d;
    }
  });
  return out;
}

namespace {

// Median labels of the anchors of row y for BilateralMedianPrune: med[x] is
// the colour-weighted median label of the (2r + 1)^2 window around anchor
// (x, y), -1 where (x, y) is no anchor. `label`, the colour `planes` and
// `anchor` (1 at anchors, else 0) are padded by 8 past the image; hist (bins
// zeros, left zeroed) and wgt (2r + 8 floats) are scratch.
CASUAL3D_AVX2_CLONES
void BilateralMedianRow(int y, const std::vector<int>& label, const ColorPlanes& planes,
                        const std::vector<float>& anchor, int w, int h, int r, float inv2s2, float* __restrict hist,
                        float* __restrict wgt, int* med) {
  const float* __restrict pr = planes.r.data();
  const float* __restrict pg = planes.g.data();
  const float* __restrict pb = planes.b.data();
  const float* __restrict pa = anchor.data();
  for (int x = 0; x < w; ++x) {
    const size_t c = static_cast<size_t>(y) * w + x;
    med[x] = -1;
    if (label[c] < 0) continue;
    const float r0 = pr[c], g0 = pg[c], b0 = pb[c];
    float total = 0.0f;
    LabelHistogram histogram(hist);
    const int u0 = std::max(0, x - r), u1 = std::min(w - 1, x + r), n = u1 - u0 + 1;
    for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v) {
      const size_t row = static_cast<size_t>(v) * w + u0;
      const int* __restrict lrow = label.data() + row;
      // Weights (0 where there is no anchor) in a loop that vectorises, over
      // whole blocks of 8 (the planes and labels are padded; lanes past the
      // window weigh 0).
      const int n8 = (n + 7) & ~7;
      for (int i = 0; i < n8; ++i) {
        wgt[i] = pa[row + i] * ColorAffinity(pr[row + i] - r0, pg[row + i] - g0, pb[row + i] - b0, inv2s2);
      }
      for (int i = n; i < n8; ++i) wgt[i] = 0.0f;
      for (int i = 0; i < n8; ++i) total += wgt[i];
      histogram.AddRow(lrow, wgt, n);
    }
    med[x] = histogram.MedianAndClear(total);
  }
}

}  // namespace

ImageF BilateralMedianPrune(const ImageF& depth, const ImageF& color, const LabelGrid& grid,
                            const MedianPruneOptions& options, int num_threads) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  if (color.width() != depth.width() || color.height() != depth.height() || color.channels() != 3)
    throw std::invalid_argument("bilateral median: colour image size does not match the depth map");
  const int w = depth.width(), h = depth.height(), r = options.large_radius;
  const int bins = grid.num_labels;
  const size_t n = static_cast<size_t>(w) * h;
  // Labels as integers once (WTA depths sit on labels), -1 = invalid, and 1
  // at anchors, 0 elsewhere; the colour guide as planes. All padded by 8 for
  // the weight loop's last block.
  std::vector<int> label(n + 8, -1);
  std::vector<float> anchor(n + 8, 0.0f);
  for (size_t p = 0; p < n; ++p) {
    const float d = depth.data()[p];
    if (d > 0) {
      const int k = static_cast<int>(std::lround(grid.LabelOf(d)));
      label[p] = std::min(bins - 1, std::max(0, k));
      anchor[p] = 1.0f;
    }
  }
  const ColorPlanes planes = SplitColor(color, 8);
  // Colour weights exp(-|c_q - c_p|^2 / (2 sigma_c^2)).
  const float inv2s2 = static_cast<float>(1.0 / (2.0 * options.sigma_color * options.sigma_color));

  ImageF out(w, h, 1, 0.0f);
  base::ParallelFor(0, h, base::ResolveThreads(num_threads), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    std::vector<float> hist(bins, 0.0f), wgt(2 * r + 8);
    std::vector<int> med(w);
    BilateralMedianRow(y, label, planes, anchor, w, h, r, inv2s2, hist.data(), wgt.data(), med.data());
    for (int x = 0; x < w; ++x) {
      if (med[x] < 0) continue;
      const float d = depth.at(x, y);
      if (WithinBand(d, label[static_cast<size_t>(y) * w + x], med[x], grid, options)) out.at(x, y) = d;
    }
  });
  return out;
}

}  // namespace casual3d::depth
