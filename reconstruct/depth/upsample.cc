#include "reconstruct/depth/upsample.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "reconstruct/depth/parallel.h"

namespace casual3d::depth {

Status UpsampleOptions::Check() const {
  if (radius < 1 || radius > 8) return InvalidArgument("upsample radius outside [1, 8]");
  if (!(sigma_spatial > 0 && sigma_spatial <= 16))
    return InvalidArgument("upsample sigma_spatial outside (0, 16]");
  if (!(sigma_color > 0 && sigma_color <= 10))
    return InvalidArgument("upsample sigma_color outside (0, 10]");
  if (num_threads < 0) return InvalidArgument("num_threads must be >= 0");
  return Status::Ok();
}

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
  // factors exp(-d^2 / (2 sigma_s^2)) of its window. The colour weight
  // exp(-t) comes from a table over t in [0, kMaxT) with linear
  // interpolation (relative error below 2e-4; exp(-kMaxT) is 2e-9).
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
  constexpr float kMaxT = 20.0f;
  constexpr int kTable = 2048;
  std::vector<float> exp_table(kTable + 2);
  for (int i = 0; i <= kTable + 1; ++i) exp_table[i] = static_cast<float>(std::exp(-kMaxT * i / kTable));
  const float to_index = kTable / kMaxT;
  ParallelFor(0, hh, ResolveThreads(options.num_threads), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    std::vector<std::pair<float, float>> samples(static_cast<size_t>(taps) * taps);  // (value, weight)
    std::vector<float> wrow(taps);
    const double v = (y + 0.5) * sy - 0.5;
    const int vc = static_cast<int>(std::lround(v));
    factors(v, vc, wrow.data());
    for (int x = 0; x < hw; ++x) {
      const int uc = ucol[x];
      const float* wc = &wcol[static_cast<size_t>(x) * taps];
      const float* c0 = &high_color.at(x, y, 0);
      int count = 0;
      float total = 0.0f;
      for (int q = std::max(0, vc - r); q <= std::min(lh - 1, vc + r); ++q) {
        const float wq = wrow[q - vc + r];
        for (int p = std::max(0, uc - r); p <= std::min(lw - 1, uc + r); ++p) {
          const float val = low.at(p, q);
          if (!(val > 0)) continue;
          const float* c = &low_color.at(p, q, 0);
          const float dc = (c[0] - c0[0]) * (c[0] - c0[0]) + (c[1] - c0[1]) * (c[1] - c0[1]) +
                           (c[2] - c0[2]) * (c[2] - c0[2]);
          const float t = std::min(dc * inv_sc * to_index, static_cast<float>(kTable));
          const int i = static_cast<int>(t);
          const float f = t - static_cast<float>(i);
          const float wcolor = exp_table[i] + f * (exp_table[i + 1] - exp_table[i]);
          const float wgt = wq * wc[p - uc + r] * wcolor + 1e-12f;
          // Insertion into the samples sorted by value.
          int k = count++;
          while (k > 0 && samples[k - 1].first > val) {
            samples[k] = samples[k - 1];
            --k;
          }
          samples[k] = {val, wgt};
          total += wgt;
        }
      }
      if (count == 0) continue;
      float acc = 0.0f;
      float med = samples[count - 1].first;
      for (int k = 0; k < count; ++k) {
        acc += samples[k].second;
        if (acc >= 0.5f * total) {
          med = samples[k].first;
          break;
        }
      }
      out.at(x, y) = med;
    }
  });
  return out;
}

}  // namespace casual3d::depth
