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
  ParallelFor(0, hh, ResolveThreads(options.num_threads), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    std::vector<std::pair<float, float>> samples;  // (value, weight)
    samples.reserve((2 * r + 1) * (2 * r + 1));
    const double v = (y + 0.5) * sy - 0.5;
    const int vc = static_cast<int>(std::lround(v));
    for (int x = 0; x < hw; ++x) {
      const double u = (x + 0.5) * sx - 0.5;
      const int uc = static_cast<int>(std::lround(u));
      const float* c0 = &high_color.at(x, y, 0);
      samples.clear();
      float total = 0.0f;
      for (int q = std::max(0, vc - r); q <= std::min(lh - 1, vc + r); ++q) {
        for (int p = std::max(0, uc - r); p <= std::min(lw - 1, uc + r); ++p) {
          const float val = low.at(p, q);
          if (!(val > 0)) continue;
          const float* c = &low_color.at(p, q, 0);
          const float dc = (c[0] - c0[0]) * (c[0] - c0[0]) + (c[1] - c0[1]) * (c[1] - c0[1]) +
                           (c[2] - c0[2]) * (c[2] - c0[2]);
          const float ds = static_cast<float>((p - u) * (p - u) + (q - v) * (q - v));
          const float wgt = std::exp(-ds * inv_ss - dc * inv_sc) + 1e-12f;
          samples.emplace_back(val, wgt);
          total += wgt;
        }
      }
      if (samples.empty()) continue;
      std::sort(samples.begin(), samples.end());
      float acc = 0.0f;
      float med = samples.back().first;
      for (const auto& s : samples) {
        acc += s.second;
        if (acc >= 0.5f * total) {
          med = s.first;
          break;
        }
      }
      out.at(x, y) = med;
    }
  });
  return out;
}

}  // namespace casual3d::depth
