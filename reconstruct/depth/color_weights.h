#pragma once

// Colour affinities exp(-|c_q - c_p|^2 / (2 sigma^2)) of RGB pixels, the
// weights of the dense stage's edge-aware filters (the medians, the
// upsampling, the boundary relabelling). Their loops run over colour planes
// so that the compiler vectorises them.

#include <cstddef>
#include <vector>

#include "format/image.h"
#include "reconstruct/depth/fast_exp.h"

namespace casual3d::depth {

// exp(-(dr^2 + dg^2 + db^2) inv2s2), inv2s2 = 1 / (2 sigma^2) >= 0.
inline float ColorAffinity(float dr, float dg, float db, float inv2s2) {
  return ExpNonPositive(-(dr * dr + dg * dg + db * db) * inv2s2);
}

// An RGB image's channels as planes of width * height + padding floats
// each (the padding zero, for loops that run over whole vector blocks).
struct ColorPlanes {
  std::vector<float> r, g, b;
};
ColorPlanes SplitColor(const ImageF& color, size_t padding = 0);

// out[i] = ColorAffinity(r[i] - c0[0], g[i] - c0[1], b[i] - c0[2], inv2s2)
// for i < n: the weights of n gathered samples against colour c0.
void ColorWeights(const float* r, const float* g, const float* b, int n, const float* c0, float inv2s2,
                   float* out);

}  // namespace casual3d::depth
