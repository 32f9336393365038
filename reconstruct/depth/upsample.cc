#include "reconstruct/depth/upsample.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "base/parallel_for.h"
#include "reconstruct/depth/color_weights.h"

namespace casual3d::depth {

ImageF JointBilateralMedianUpsample(const ImageF& low, const ImageF& low_color,
                                    const ImageF& high_color, const UpsampleOptions& options) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  if (low_color.width() != low.width() || low_color.height() != low.height() ||
      low_color.channels() != 3 || high_color.channels() != 3)
    throw std::invalid_argument("upsample: guide images do not match");
  const int lw = low.width(), lh = low.height();
  const int hw = high_color.width(), hh = high_color.height();
  const double sx = static_cast<double>(lw) / hw, sy = static_cast<double>(lh) / hh;
  const int r = options.radius;
  const float inv_ss = static_cast<float>(1.0 / (2 * options.sigma_spatial * options.sigma_spatial));
  const float inv_sc = static_cast<float>(1.0 / (2 * options.sigma_color * options.sigma_color));
  ImageF out(hw, hh, 1, 0.0f);
  // The spatial weight is separable: per column and per row, the 2r + 1
  // factors exp(-d^2 / (2 sigma_s^2)) of its window. The colour weights
  // are computed per sample (ColorWeights).
  const int taps = 2 * r + 1;
  std::vector<int> ucol(hw);
  std::vector<float> wcol(static_cast<size_t>(hw) * taps);
  auto factors = [&](double centre, int c, float* out_w) {
    for (int k = 0; k < taps; ++k) {
      const double d = c - r + k - centre;
      out_w[k] = static_cast<float>(std::exp(-d * d * inv_ss));
    }
  };
  for (int x = 0; x < hw; ++x) {
    const double u = (x + 0.5) * sx - 0.5;
    ucol[x] = static_cast<int>(std::lround(u));
    factors(u, ucol[x], &wcol[static_cast<size_t>(x) * taps]);
  }
  // Pixels of a row that share a low-resolution window (two in a row at
  // half resolution) share its samples' order by value: the window's valid
  // samples are sorted once (stably, in scanning order among equal values)
  // and each pixel only weighs them, then walks them in that order to its
  // weighted median.
  base::ParallelFor(0, hh, base::ResolveThreads(options.num_threads), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    const size_t max_samples = static_cast<size_t>(taps) * taps;
    std::vector<float> value(max_samples), weight(max_samples), spatial(max_samples);
    std::vector<float> sr(max_samples), sg(max_samples), sb(max_samples);
    std::vector<int> column(max_samples), order(max_samples);
    std::vector<float> wrow(taps);
    const double v = (y + 0.5) * sy - 0.5;
    const int vc = static_cast<int>(std::lround(v));
    factors(v, vc, wrow.data());
    const int q0 = std::max(0, vc - r), q1 = std::min(lh - 1, vc + r);
    int window_uc = -1, count = 0;  // No window yet: every ucol is >= 0.
    for (int x = 0; x < hw; ++x) {
      const int uc = ucol[x];
      if (uc != window_uc) {
        // The window's valid samples in scanning order, then their order by value.
        window_uc = uc;
        count = 0;
        for (int q = q0; q <= q1; ++q)
          for (int p = std::max(0, uc - r); p <= std::min(lw - 1, uc + r); ++p) {
            const float val = low.at(p, q);
            if (!(val > 0)) continue;
            value[count] = val;
            const float* c = &low_color.at(p, q, 0);
            sr[count] = c[0];
            sg[count] = c[1];
            sb[count] = c[2];
            spatial[count] = wrow[q - vc + r];
            column[count] = p - uc + r;
            int k = count;
            while (k > 0 && value[order[k - 1]] > val) {
              order[k] = order[k - 1];
              --k;
            }
            order[k] = count;
            ++count;
          }
      }
      if (count == 0) continue;
      const float* wc = &wcol[static_cast<size_t>(x) * taps];
      const float* c0 = &high_color.at(x, y, 0);
      ColorWeights(sr.data(), sg.data(), sb.data(), count, c0, inv_sc, weight.data());
      float total = 0.0f;
      for (int s = 0; s < count; ++s) {
        weight[s] = spatial[s] * wc[column[s]] * weight[s] + 1e-12f;
        total += weight[s];
      }
      float acc = 0.0f;
      float med = value[order[count - 1]];
      for (int k = 0; k < count; ++k) {
        acc += weight[order[k]];
        if (acc >= 0.5f * total) {
          med = value[order[k]];
          break;
        }
      }
      out.at(x, y) = med;
    }
  });
  return out;
}

}  // namespace casual3d::depth
