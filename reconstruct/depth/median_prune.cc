#include "reconstruct/depth/median_prune.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "reconstruct/depth/parallel.h"

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

Status MedianPruneOptions::Check() const {
  if (small_radius < 1 || small_radius > 64)
    return InvalidArgument("small median radius " + std::to_string(small_radius) +
                           " outside [1, 64]");
  if (large_radius < 1 || large_radius > 256)
    return InvalidArgument("large median radius " + std::to_string(large_radius) +
                           " outside [1, 256]");
  if (!(small_min_valid >= 0 && small_min_valid <= 1))
    return InvalidArgument("small_min_valid outside [0, 1]");
  if (!(sigma_color > 0 && sigma_color <= 10)) return InvalidArgument("sigma_color outside (0, 10]");
  if (!(band_low > 0 && band_low <= 1 && band_high >= 1))
    return InvalidArgument("median band must satisfy 0 < band_low <= 1 <= band_high");
  return Status::Ok();
}

ImageF MedianPrune(const ImageF& depth, const LabelGrid& grid, const MedianPruneOptions& options,
                   int num_threads) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  const int w = depth.width(), h = depth.height(), r = options.small_radius;
  ImageF out(w, h, 1, 0.0f);
  ParallelFor(0, h, ResolveThreads(num_threads), [&](int64_t yy) {
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

ImageF BilateralMedianPrune(const ImageF& depth, const ImageF& color, const LabelGrid& grid,
                            const MedianPruneOptions& options, int num_threads) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  if (color.width() != depth.width() || color.height() != depth.height() || color.channels() != 3)
    throw std::invalid_argument("bilateral median: colour image size does not match the depth map");
  const int w = depth.width(), h = depth.height(), r = options.large_radius;
  const int bins = grid.num_labels;
  // Labels as integers once (WTA depths sit on labels), -1 = invalid.
  std::vector<int> label(static_cast<size_t>(w) * h, -1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float d = depth.at(x, y);
      if (d > 0) {
        const int k = static_cast<int>(std::lround(grid.LabelOf(d)));
        label[static_cast<size_t>(y) * w + x] = std::min(bins - 1, std::max(0, k));
      }
    }
  // exp(-dist^2 / (2 sigma^2)) tabulated on squared colour distance.
  constexpr int kLut = 4096;
  const double max_d2 = 3.0;
  std::vector<float> lut(kLut + 1);
  for (int i = 0; i <= kLut; ++i)
    lut[i] = static_cast<float>(
        std::exp(-(max_d2 * i / kLut) / (2 * options.sigma_color * options.sigma_color)));
  const float lut_scale = kLut / max_d2;

  ImageF out(w, h, 1, 0.0f);
  ParallelFor(0, h, ResolveThreads(num_threads), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    std::vector<float> hist(bins);
    for (int x = 0; x < w; ++x) {
      const int k0 = label[static_cast<size_t>(y) * w + x];
      if (k0 < 0) continue;
      std::fill(hist.begin(), hist.end(), 0.0f);
      const float* c0 = &color.at(x, y, 0);
      float total = 0.0f;
      int kmin = bins, kmax = -1;
      for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v) {
        const int* lrow = label.data() + static_cast<size_t>(v) * w;
        const float* crow = color.row(v);
        for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u) {
          const int k = lrow[u];
          if (k < 0) continue;
          const float* c = crow + 3 * u;
          const float d0 = c[0] - c0[0], d1 = c[1] - c0[1], d2 = c[2] - c0[2];
          const float d = std::min(static_cast<float>(max_d2), d0 * d0 + d1 * d1 + d2 * d2);
          const float wgt = lut[static_cast<int>(d * lut_scale)];
          hist[k] += wgt;
          total += wgt;
          kmin = std::min(kmin, k);
          kmax = std::max(kmax, k);
        }
      }
      float acc = 0.0f;
      int med = kmin;
      for (int k = kmin; k <= kmax; ++k) {
        acc += hist[k];
        if (acc >= 0.5f * total) {
          med = k;
          break;
        }
      }
      const float d = depth.at(x, y);
      if (WithinBand(d, k0, med, grid, options)) out.at(x, y) = d;
    }
  });
  return out;
}

}  // namespace casual3d::depth
