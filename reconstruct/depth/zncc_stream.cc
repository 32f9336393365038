#include "reconstruct/depth/zncc_stream.h"

namespace casual3d::depth {

void BoxMean(const float* in, float* out, int w, int h, int r, float* tmp, float* acc,
             const float* inv_count) {
  // Horizontal sums with a running window.
  for (int y = 0; y < h; ++y) {
    const float* row = in + static_cast<size_t>(y) * w;
    float* dst = tmp + static_cast<size_t>(y) * w;
    float s = 0.0f;
    for (int x = 0; x < std::min(r, w); ++x) s += row[x];
    for (int x = 0; x < w; ++x) {
      if (x + r < w) s += row[x + r];
      if (x - r - 1 >= 0) s -= row[x - r - 1];
      dst[x] = s;
    }
  }
  // Vertical running sums over whole rows (contiguous, vectorisable).
  std::fill(acc, acc + w, 0.0f);
  for (int y = 0; y < std::min(r, h); ++y) {
    const float* row = tmp + static_cast<size_t>(y) * w;
    for (int x = 0; x < w; ++x) acc[x] += row[x];
  }
  for (int y = 0; y < h; ++y) {
    if (y + r < h) {
      const float* add = tmp + static_cast<size_t>(y + r) * w;
      for (int x = 0; x < w; ++x) acc[x] += add[x];
    }
    if (y - r - 1 >= 0) {
      const float* sub = tmp + static_cast<size_t>(y - r - 1) * w;
      for (int x = 0; x < w; ++x) acc[x] -= sub[x];
    }
    float* dst = out + static_cast<size_t>(y) * w;
    const float* ic = inv_count + static_cast<size_t>(y) * w;
    for (int x = 0; x < w; ++x) dst[x] = acc[x] * ic[x];
  }
}

ReferenceWindows ComputeReferenceWindows(const float* gray, int w, int h, int r, float epsilon) {
  const size_t n = static_cast<size_t>(w) * h;
  ReferenceWindows out;
  out.inv_count.resize(n);
  out.mean.resize(n);
  out.inv_std.resize(n);
  out.variance.resize(n);
  for (int y = 0; y < h; ++y) {
    const int ny = std::min(y + r, h - 1) - std::max(y - r, 0) + 1;
    for (int x = 0; x < w; ++x) {
      const int nx = std::min(x + r, w - 1) - std::max(x - r, 0) + 1;
      out.inv_count[static_cast<size_t>(y) * w + x] = 1.0f / static_cast<float>(nx * ny);
    }
  }
  std::vector<float> squares(n), tmp(n), acc(w);
  for (size_t i = 0; i < n; ++i) squares[i] = gray[i] * gray[i];
  BoxMean(gray, out.mean.data(), w, h, r, tmp.data(), acc.data(), out.inv_count.data());
  BoxMean(squares.data(), out.variance.data(), w, h, r, tmp.data(), acc.data(), out.inv_count.data());
  for (size_t i = 0; i < n; ++i) {
    const float var = std::max(0.0f, out.variance[i] - out.mean[i] * out.mean[i]);
    out.variance[i] = var;
    out.inv_std[i] = 1.0f / std::sqrt(var + epsilon);
  }
  return out;
}

}  // namespace casual3d::depth
