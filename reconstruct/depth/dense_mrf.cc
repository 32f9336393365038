#include "reconstruct/depth/dense_mrf.h"

#include <algorithm>
#include <cmath>

namespace casual3d::depth {

void AssembleDenseMrf(const ImageF& photo_weight, const ImageF& color, const std::vector<float>& flat_prior,
                      const ImageF& envelope, const LabelGrid& grid, const MrfTermOptions& options,
                      GridMrf* mrf) {
  const int w = mrf->width, h = mrf->height, L = mrf->num_labels;
  const size_t np = static_cast<size_t>(w) * h;
  mrf->truncation = options.truncation_labels;
  for (size_t p = 0; p < np; ++p) {
    const float wp = photo_weight.data()[p];
    float* u = mrf->unary.data() + p * L;
    const bool has_prior = !flat_prior.empty() && !std::isnan(flat_prior[p]);
    const float bias = has_prior ? 0.0f : static_cast<float>(options.far_bias) * (1.0f - wp) / (L - 1);
    for (int k = 0; k < L; ++k) u[k] = wp * u[k] + bias * static_cast<float>(L - 1 - k);
    if (has_prior) {
      // Linear in the label distance up to flat_truncation labels.
      const float tf = static_cast<float>(options.flat_truncation_labels);
      const float lp = static_cast<float>(options.lambda_flat) * (1.0f - wp) / tf;
      for (int k = 0; k < L; ++k) u[k] += lp * std::min(tf, std::abs(k - flat_prior[p]));
    }
    if (!envelope.empty()) {
      // Eq. 4: labels nearer than the envelope (k < label of n_i) pay lambda_near.
      const double kn = grid.LabelOf(envelope.data()[p]);
      const int kmax = std::min(L, static_cast<int>(std::ceil(kn)));
      for (int k = 0; k < kmax; ++k) u[k] += static_cast<float>(options.lambda_near);
    }
  }
  mrf->weight_right.assign(np, 0.0f);
  mrf->weight_down.assign(np, 0.0f);
  // In double precision with std::exp, not color_weights.h's float fast
  // exponential: the weights, and so the solved labels, stay those of the
  // stage's reference outputs.
  const double inv2s2 = 1.0 / (2.0 * options.sigma_color * options.sigma_color);
  const double scale = options.lambda_smooth / options.truncation_labels;
  auto wcolor = [&](int x0, int y0, int x1, int y1) {
    double d2 = 0;
    for (int c = 0; c < 3; ++c) {
      const double e = color.at(x0, y0, c) - color.at(x1, y1, c);
      d2 += e * e;
    }
    return static_cast<float>(scale * std::max(options.color_floor, std::exp(-d2 * inv2s2)));
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      if (x + 1 < w) mrf->weight_right[p] = wcolor(x, y, x + 1, y);
      if (y + 1 < h) mrf->weight_down[p] = wcolor(x, y, x, y + 1);
    }
}

}  // namespace casual3d::depth
