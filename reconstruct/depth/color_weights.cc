#include "reconstruct/depth/color_weights.h"

#include <stdexcept>

#include "reconstruct/depth/avx2_clones.h"

namespace casual3d::depth {

ColorPlanes SplitColor(const ImageF& color, size_t padding) {
  if (color.channels() != 3) throw std::invalid_argument("SplitColor: the image needs 3 channels");
  const size_t n = static_cast<size_t>(color.width()) * color.height();
  ColorPlanes planes;
  planes.r.assign(n + padding, 0.0f);
  planes.g.assign(n + padding, 0.0f);
  planes.b.assign(n + padding, 0.0f);
  const float* c = color.data();
  for (size_t i = 0; i < n; ++i) {
    planes.r[i] = c[3 * i];
    planes.g[i] = c[3 * i + 1];
    planes.b[i] = c[3 * i + 2];
  }
  return planes;
}

CASUAL3D_AVX2_CLONES
void ColorWeights(const float* __restrict r, const float* __restrict g, const float* __restrict b, int n,
                   const float* c0, float inv2s2, float* __restrict out) {
  const float r0 = c0[0], g0 = c0[1], b0 = c0[2];
  for (int i = 0; i < n; ++i) out[i] = ColorAffinity(r[i] - r0, g[i] - g0, b[i] - b0, inv2s2);
}

}  // namespace casual3d::depth
