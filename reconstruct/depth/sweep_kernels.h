#pragma once

// Row kernels of the plane sweep (plane_sweep.cc): the loops that run once per
// pixel x plane x neighbour. Each works on one image row held in cache, so the
// sweep streams through a plane row by row without whole-image temporaries.
// On x86-64 the warp, the best-k mean and the layout change use SSE2
// intrinsics (the baseline of every x86-64 CPU); the other loops are plain
// loops that GCC and Clang vectorise, compiled for AVX2 too where GCC offers
// it (avx2_clones.h). Results do not depend on the code path: every lane
// computes the same IEEE float expression, in the same order, as the scalar
// fallback. (The warp stays SSE2 with scalar corner loads: docs/DECISIONS.md,
// "Dense: loops that vectorise".)

#include <algorithm>
#include <cstddef>

namespace casual3d::depth::sweep {

// Bilinear sample of a 1-channel w x h row-major image at pixel-index
// coordinates (x, y) (pixel centres at integers), clamped to the border
// (window pixels that fall just outside the neighbour keep a sensible value;
// callers check the centre's own validity).
inline float Bilinear(const float* img, int w, int h, float x, float y) {
  x = std::min(std::max(x, 0.0f), static_cast<float>(w - 1));
  y = std::min(std::max(y, 0.0f), static_cast<float>(h - 1));
  const int x0 = std::min(static_cast<int>(x), w - 2 < 0 ? 0 : w - 2);
  const int y0 = std::min(static_cast<int>(y), h - 2 < 0 ? 0 : h - 2);
  const float fx = x - x0, fy = y - y0;
  const float* p = img + static_cast<size_t>(y0) * w + x0;
  const int dx = w > 1 ? 1 : 0;
  const size_t dy = h > 1 ? static_cast<size_t>(w) : 0;
  const float top = p[0] + fx * (p[dx] - p[0]);
  const float bot = p[dy] + fx * (p[dy + dx] - p[dy]);
  return top + fy * (bot - top);
}

// Cost of a neighbour that does not see the pixel; larger than any real cost
// (costs are in [0, 1]) so that sorting puts it last.
constexpr float kInvalidCost = 2.0f;

// One row of a plane-induced homography in homogeneous neighbour pixel
// coordinates: the pixel x of the row maps to p0 + x * step (3-vectors). The
// reference pixel centre convention of view.h is folded into p0.
struct HomographyRow {
  float p0[3] = {0, 0, 0};
  float step[3] = {0, 0, 0};
};

// Warps one row of `width` pixels. For pixel x with p = p0 + x * step and
// p.z > 1e-9, the neighbour position is (p.x / p.z - 0.5, p.y / p.z - 0.5)
// (pixel indices). If it lies within [-0.5, src_width - 0.5] x
// [-0.5, src_height - 0.5], values[x] is the bilinear sample of `src`
// (src_width x src_height, row-major, clamped to the border) and invalid[x] is
// 0; otherwise values[x] = 0 and invalid[x] = kInvalidCost.
void WarpRow(const float* src, int src_width, int src_height, const HomographyRow& row, int width,
             float* values, float* invalid);

// WarpRow with a plane per pixel: pixel x's homogeneous neighbour coordinates
// are p0 + x * step + inv[x] * b (the homography of the fronto-parallel plane
// at inverse depth inv[x], view.h's x_n ~ a x_ref + (1/d) b), otherwise the
// same inside test, sampling and outputs.
void WarpRowPerPixel(const float* src, int src_width, int src_height, const HomographyRow& row,
                     const float* inv, const float b[3], int width, float* values, float* invalid);

// The three window sums of the ZNCC for one warped row at once. `j` is the
// warped row and `i` the reference's, both padded with r zeros on each side
// (width + 2r elements). For x in [0, width): out[0][x] is the sum of j over
// the window [x, x + 2r], out[1][x] that of j*j and out[2][x] that of j*i
// (each product rounded, then summed in window order), and each is added to its
// running total acc[k][x]; with `old` (else nullptr), old[k][x] is then
// subtracted from it: acc = (acc + out) - old. No output may overlap an
// input.
void ZnccWindowSums(const float* j, const float* i, int width, int r, float* const out[3],
                    float* const acc[3], const float* const old[3]);

// acc[x] -= sub[x] for x in [0, width).
void SubtractRow(const float* sub, int width, float* acc);

// Per-pixel inputs of the ZNCC of one row.
struct ZnccRowInputs {
  const float* sum_j = nullptr;      // Window sum of the warped neighbour J.
  const float* sum_jj = nullptr;     // Window sum of J^2.
  const float* sum_ij = nullptr;     // Window sum of I * J (I = reference grey).
  const float* inv_count = nullptr;  // 1 / number of window pixels.
  const float* mean_i = nullptr;     // Window mean of I.
  const float* inv_std_i = nullptr;  // 1 / sqrt(var(I) + epsilon).
  const float* invalid = nullptr;    // 0 where the neighbour sees the pixel, else kInvalidCost.
};

// cost[x] = min(1, max(0, 1 - ZNCC)) with ZNCC = cov(I, J) / sqrt((var I +
// epsilon)(var J + epsilon)), or kInvalidCost where in.invalid[x] != 0.
void ZnccCostRow(const ZnccRowInputs& in, float epsilon, int width, float* cost);

// Keeps, per pixel, the k smallest costs seen so far in ascending order:
// slots holds k rows of `width` (slot q of pixel x at slots[q * width + x]),
// initialised to kInvalidCost; this inserts cost[x] into pixel x's list.
void InsertSmallest(const float* cost, int width, int k, float* slots);

// out[x] = mean of pixel x's valid (< kInvalidCost) slots, each capped at the
// best slot's cost plus `truncation`, or 1 if none is valid.
void MeanOfSlots(const float* slots, int width, int k, float truncation, float* out);

// Writes `num_planes` plane-major rows of `n` values (planes[g * n + p]) into a
// pixel-major array: out[p * stride + g] = planes[g * n + p].
void PlanesToPixelMajor(const float* planes, size_t n, int num_planes, float* out, size_t stride);

}  // namespace casual3d::depth::sweep
