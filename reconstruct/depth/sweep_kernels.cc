#include "reconstruct/depth/sweep_kernels.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "reconstruct/depth/avx2_clones.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#include <xmmintrin.h>
#endif

namespace casual3d::depth::sweep {
namespace {

// With `inv` set, the pixel's own inverse depth adds inv[x] * b (a
// per-pixel plane); otherwise b is not read.
inline void WarpPixel(const float* src, int sw, int sh, const HomographyRow& row, const float* inv,
                      const float* b, int x, float* value, float* invalid) {
  const float xf = static_cast<float>(x);
  float px = row.p0[0] + row.step[0] * xf;
  float py = row.p0[1] + row.step[1] * xf;
  float pz = row.p0[2] + row.step[2] * xf;
  if (inv) {
    px += b[0] * inv[x];
    py += b[1] * inv[x];
    pz += b[2] * inv[x];
  }
  float val = 0.0f;
  bool inside = false;
  if (pz > 1e-9f) {
    const float iz = 1.0f / pz;
    const float u = px * iz - 0.5f, v = py * iz - 0.5f;
    inside = u >= -0.5f && v >= -0.5f && u <= sw - 0.5f && v <= sh - 0.5f;
    if (inside) val = Bilinear(src, sw, sh, u, v);
  }
  *value = val;
  *invalid = inside ? 0.0f : kInvalidCost;
}

#if defined(__SSE2__)
// (a[0], a[1], b[0], b[1]).
inline __m128 LoadPairs(const float* a, const float* b) {
  const __m128 lo = _mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(a)));
  return _mm_castpd_ps(_mm_loadh_pd(_mm_castps_pd(lo), reinterpret_cast<const double*>(b)));
}
#endif

}  // namespace

namespace {

// WarpRow and WarpRowPerPixel: kPerPixel adds inv[x] * b to each pixel's
// homogeneous coordinates.
template <bool kPerPixel>
void WarpRowImpl(const float* src, int sw, int sh, const HomographyRow& row, const float* inv,
                 const float* b, int width, float* values, float* invalid) {
  int x = 0;
#if defined(__SSE2__)
  // Four pixels at a time: coordinates, the inside test, clamping and the
  // interpolation weights in SIMD; the four corner loads per pixel are scalar
  // (SSE2 has no gather). Lanes whose centre is outside (or behind the
  // camera, where u may be NaN or infinite) are clamped to a valid address
  // and masked to 0 afterwards.
  const __m128 zero = _mm_setzero_ps();
  const __m128 half = _mm_set1_ps(0.5f), minus_half = _mm_set1_ps(-0.5f);
  const __m128 umax = _mm_set1_ps(sw - 0.5f), vmax = _mm_set1_ps(sh - 0.5f);
  const __m128 wm1 = _mm_set1_ps(static_cast<float>(sw - 1));
  const __m128 hm1 = _mm_set1_ps(static_cast<float>(sh - 1));
  const __m128 x0max = _mm_set1_ps(static_cast<float>(sw - 2 < 0 ? 0 : sw - 2));
  const __m128 y0max = _mm_set1_ps(static_cast<float>(sh - 2 < 0 ? 0 : sh - 2));
  const __m128 zmin = _mm_set1_ps(1e-9f);
  const __m128 one = _mm_set1_ps(1.0f);
  const __m128 invalid_cost = _mm_set1_ps(kInvalidCost);
  const __m128 sx = _mm_set1_ps(row.step[0]), sy = _mm_set1_ps(row.step[1]),
               sz = _mm_set1_ps(row.step[2]);
  const __m128 ox = _mm_set1_ps(row.p0[0]), oy = _mm_set1_ps(row.p0[1]),
               oz = _mm_set1_ps(row.p0[2]);
  const int dx = sw > 1 ? 1 : 0;
  const size_t dy = sh > 1 ? static_cast<size_t>(sw) : 0;
  alignas(16) int32_t ix[4], iy[4];
  for (; x + 4 <= width; x += 4) {
    const __m128 xf = _mm_cvtepi32_ps(_mm_setr_epi32(x, x + 1, x + 2, x + 3));
    __m128 px = _mm_add_ps(ox, _mm_mul_ps(sx, xf));
    __m128 py = _mm_add_ps(oy, _mm_mul_ps(sy, xf));
    __m128 pz = _mm_add_ps(oz, _mm_mul_ps(sz, xf));
    if constexpr (kPerPixel) {
      const __m128 d = _mm_loadu_ps(inv + x);
      px = _mm_add_ps(px, _mm_mul_ps(_mm_set1_ps(b[0]), d));
      py = _mm_add_ps(py, _mm_mul_ps(_mm_set1_ps(b[1]), d));
      pz = _mm_add_ps(pz, _mm_mul_ps(_mm_set1_ps(b[2]), d));
    }
    const __m128 front = _mm_cmpgt_ps(pz, zmin);
    const __m128 iz = _mm_div_ps(one, pz);
    const __m128 u = _mm_sub_ps(_mm_mul_ps(px, iz), half);
    const __m128 v = _mm_sub_ps(_mm_mul_ps(py, iz), half);
    __m128 inside =
        _mm_and_ps(front, _mm_and_ps(_mm_cmpge_ps(u, minus_half), _mm_cmpge_ps(v, minus_half)));
    inside = _mm_and_ps(inside, _mm_and_ps(_mm_cmple_ps(u, umax), _mm_cmple_ps(v, vmax)));
    if (_mm_movemask_ps(inside) == 0) {
      _mm_storeu_ps(values + x, zero);
      _mm_storeu_ps(invalid + x, invalid_cost);
      continue;
    }
    // max(u, 0) returns 0 for NaN lanes (the second operand wins).
    const __m128 uc = _mm_min_ps(_mm_max_ps(u, zero), wm1);
    const __m128 vc = _mm_min_ps(_mm_max_ps(v, zero), hm1);
    const __m128 x0 = _mm_min_ps(_mm_cvtepi32_ps(_mm_cvttps_epi32(uc)), x0max);
    const __m128 y0 = _mm_min_ps(_mm_cvtepi32_ps(_mm_cvttps_epi32(vc)), y0max);
    const __m128 fx = _mm_sub_ps(uc, x0), fy = _mm_sub_ps(vc, y0);
    _mm_store_si128(reinterpret_cast<__m128i*>(ix), _mm_cvttps_epi32(x0));
    _mm_store_si128(reinterpret_cast<__m128i*>(iy), _mm_cvttps_epi32(y0));
    // Corner values go straight into registers (storing them and reloading
    // as a vector would stall on store forwarding); horizontally adjacent
    // corners come in pairs with one 64-bit load each.
    const float* q0 = src + static_cast<size_t>(iy[0]) * sw + ix[0];
    const float* q1 = src + static_cast<size_t>(iy[1]) * sw + ix[1];
    const float* q2 = src + static_cast<size_t>(iy[2]) * sw + ix[2];
    const float* q3 = src + static_cast<size_t>(iy[3]) * sw + ix[3];
    __m128 p00, p01, p10, p11;
    if (dx == 1) {
      const __m128 t01 = LoadPairs(q0, q1), t23 = LoadPairs(q2, q3);
      const __m128 b01 = LoadPairs(q0 + dy, q1 + dy), b23 = LoadPairs(q2 + dy, q3 + dy);
      p00 = _mm_shuffle_ps(t01, t23, _MM_SHUFFLE(2, 0, 2, 0));
      p01 = _mm_shuffle_ps(t01, t23, _MM_SHUFFLE(3, 1, 3, 1));
      p10 = _mm_shuffle_ps(b01, b23, _MM_SHUFFLE(2, 0, 2, 0));
      p11 = _mm_shuffle_ps(b01, b23, _MM_SHUFFLE(3, 1, 3, 1));
    } else {
      p00 = p01 = _mm_setr_ps(q0[0], q1[0], q2[0], q3[0]);
      p10 = p11 = _mm_setr_ps(q0[dy], q1[dy], q2[dy], q3[dy]);
    }
    const __m128 top = _mm_add_ps(p00, _mm_mul_ps(fx, _mm_sub_ps(p01, p00)));
    const __m128 bot = _mm_add_ps(p10, _mm_mul_ps(fx, _mm_sub_ps(p11, p10)));
    const __m128 val = _mm_add_ps(top, _mm_mul_ps(fy, _mm_sub_ps(bot, top)));
    _mm_storeu_ps(values + x, _mm_and_ps(inside, val));
    _mm_storeu_ps(invalid + x, _mm_andnot_ps(inside, invalid_cost));
  }
#endif
  for (; x < width; ++x) WarpPixel(src, sw, sh, row, kPerPixel ? inv : nullptr, b, x, values + x, invalid + x);
}

}  // namespace

void WarpRow(const float* src, int sw, int sh, const HomographyRow& row, int width, float* values,
             float* invalid) {
  WarpRowImpl<false>(src, sw, sh, row, nullptr, nullptr, width, values, invalid);
}

void WarpRowPerPixel(const float* src, int sw, int sh, const HomographyRow& row, const float* inv,
                     const float b[3], int width, float* values, float* invalid) {
  WarpRowImpl<true>(src, sw, sh, row, inv, b, width, values, invalid);
}

namespace {

// ZnccWindowSums with kTaps (> 0) known at compile time, so that the taps
// unroll; 0: `taps` taps. With kSubtract, old rows leave the totals.
template <int kTaps, bool kSubtract>
__attribute__((always_inline)) inline void ZnccWindowSumsFixed(
    const float* __restrict j, const float* __restrict i, int width, int taps_any, float* __restrict oj,
    float* __restrict ojj, float* __restrict oij, float* __restrict aj, float* __restrict ajj,
    float* __restrict aij, const float* __restrict pj, const float* __restrict pjj, const float* __restrict pij) {
  const int taps = kTaps > 0 ? kTaps : taps_any;
  for (int x = 0; x < width; ++x) {
    float sj = j[x], sjj = j[x] * j[x], sij = j[x] * i[x];
    for (int d = 1; d < taps; ++d) {
      const float v = j[x + d];
      sj += v;
      sjj += v * v;
      sij += v * i[x + d];
    }
    oj[x] = sj;
    ojj[x] = sjj;
    oij[x] = sij;
    if constexpr (kSubtract) {
      aj[x] = (aj[x] + sj) - pj[x];
      ajj[x] = (ajj[x] + sjj) - pjj[x];
      aij[x] = (aij[x] + sij) - pij[x];
    } else {
      aj[x] += sj;
      ajj[x] += sjj;
      aij[x] += sij;
    }
  }
}

template <bool kSubtract>
__attribute__((always_inline)) inline void ZnccWindowSumsTaps(const float* j, const float* i, int width, int r,
                                                              float* const out[3], float* const acc[3],
                                                              const float* const old[3]) {
  const float* pj = kSubtract ? old[0] : nullptr;
  const float* pjj = kSubtract ? old[1] : nullptr;
  const float* pij = kSubtract ? old[2] : nullptr;
#define CASUAL3D_ZNCC_SUMS(T)                                                                                 \
  ZnccWindowSumsFixed<T, kSubtract>(j, i, width, 2 * r + 1, out[0], out[1], out[2], acc[0], acc[1], acc[2], pj, \
                                    pjj, pij)
  switch (r) {
    case 1:
      return CASUAL3D_ZNCC_SUMS(3);
    case 2:
      return CASUAL3D_ZNCC_SUMS(5);
    case 3:
      return CASUAL3D_ZNCC_SUMS(7);
    case 4:
      return CASUAL3D_ZNCC_SUMS(9);
    case 5:  // The full-resolution search's 11x11 window.
      return CASUAL3D_ZNCC_SUMS(11);
    case 6:
      return CASUAL3D_ZNCC_SUMS(13);
    case 7:
      return CASUAL3D_ZNCC_SUMS(15);
    default:
      return CASUAL3D_ZNCC_SUMS(0);
  }
#undef CASUAL3D_ZNCC_SUMS
}

}  // namespace

CASUAL3D_AVX2_CLONES
void ZnccWindowSums(const float* j, const float* i, int width, int r, float* const out[3], float* const acc[3],
                    const float* const old[3]) {
  if (old) {
    ZnccWindowSumsTaps<true>(j, i, width, r, out, acc, old);
  } else {
    ZnccWindowSumsTaps<false>(j, i, width, r, out, acc, old);
  }
}

CASUAL3D_AVX2_CLONES
void SubtractRow(const float* sub, int width, float* acc) {
  const float* __restrict a = sub;
  float* __restrict out = acc;
  for (int x = 0; x < width; ++x) out[x] -= a[x];
}

CASUAL3D_AVX2_CLONES
void ZnccCostRow(const ZnccRowInputs& in, float epsilon, int width, float* cost) {
  const float* __restrict sj = in.sum_j;
  const float* __restrict sjj = in.sum_jj;
  const float* __restrict sij = in.sum_ij;
  const float* __restrict ic = in.inv_count;
  const float* __restrict mi = in.mean_i;
  const float* __restrict isi = in.inv_std_i;
  const float* __restrict inv = in.invalid;
  float* __restrict out = cost;
  for (int x = 0; x < width; ++x) {
    const float mj = sj[x] * ic[x];
    const float var_j = std::max(0.0f, sjj[x] * ic[x] - mj * mj);
    const float cov = sij[x] * ic[x] - mi[x] * mj;
    const float ncc = cov * isi[x] / std::sqrt(var_j + epsilon);
    const float e = std::min(1.0f, std::max(0.0f, 1.0f - ncc));
    out[x] = inv[x] == 0.0f ? e : kInvalidCost;
  }
}

CASUAL3D_AVX2_CLONES
void InsertSmallest(const float* cost, int width, int k, float* slots) {
  // A branch-free insertion step per slot (the smaller value stays, the
  // larger moves on to the next slot), so that the loop over pixels
  // vectorises. `carry` holds the value still looking for its slot.
  constexpr int kChunk = 256;
  float carry[kChunk];
  for (int x0 = 0; x0 < width; x0 += kChunk) {
    const int n = std::min(kChunk, width - x0);
    std::copy(cost + x0, cost + x0 + n, carry);
    for (int q = 0; q < k; ++q) {
      float* __restrict s = slots + static_cast<size_t>(q) * width + x0;
      for (int x = 0; x < n; ++x) {
        const float a = s[x], b = carry[x];
        s[x] = std::min(a, b);
        carry[x] = std::max(a, b);
      }
    }
  }
}

void MeanOfSlots(const float* slots, int width, int k, float truncation, float* out) {
  int x = 0;
#if defined(__SSE2__)
  const __m128 invalid = _mm_set1_ps(kInvalidCost), one = _mm_set1_ps(1.0f);
  const __m128 trunc = _mm_set1_ps(truncation);
  for (; x + 4 <= width; x += 4) {
    // Ascending slot order: the same summation order as sorting the costs.
    const __m128 cap = _mm_add_ps(_mm_loadu_ps(slots + x), trunc);
    __m128 sum = _mm_setzero_ps(), count = _mm_setzero_ps();
    for (int q = 0; q < k; ++q) {
      const __m128 v = _mm_loadu_ps(slots + static_cast<size_t>(q) * width + x);
      const __m128 valid = _mm_cmplt_ps(v, invalid);
      sum = _mm_add_ps(sum, _mm_and_ps(valid, _mm_min_ps(v, cap)));
      count = _mm_add_ps(count, _mm_and_ps(valid, one));
    }
    const __m128 mean = _mm_div_ps(sum, _mm_max_ps(count, one));
    const __m128 seen = _mm_cmpgt_ps(count, _mm_setzero_ps());
    _mm_storeu_ps(out + x, _mm_or_ps(_mm_and_ps(seen, mean), _mm_andnot_ps(seen, one)));
  }
#endif
  for (; x < width; ++x) {
    const float cap = slots[x] + truncation;
    float sum = 0.0f, count = 0.0f;
    for (int q = 0; q < k; ++q) {
      const float v = slots[static_cast<size_t>(q) * width + x];
      if (v < kInvalidCost) {
        sum += std::min(v, cap);
        count += 1.0f;
      }
    }
    out[x] = count > 0.0f ? sum / count : 1.0f;
  }
}

void PlanesToPixelMajor(const float* planes, size_t n, int num_planes, float* out, size_t stride) {
  int g = 0;
#if defined(__SSE2__)
  // 4 x 4 blocks: four planes of four pixels, transposed in registers.
  for (; g + 4 <= num_planes; g += 4) {
    const float* r0 = planes + static_cast<size_t>(g) * n;
    const float* r1 = r0 + n;
    const float* r2 = r1 + n;
    const float* r3 = r2 + n;
    size_t p = 0;
    for (; p + 4 <= n; p += 4) {
      __m128 a = _mm_loadu_ps(r0 + p), b = _mm_loadu_ps(r1 + p);
      __m128 c = _mm_loadu_ps(r2 + p), d = _mm_loadu_ps(r3 + p);
      _MM_TRANSPOSE4_PS(a, b, c, d);
      _mm_storeu_ps(out + p * stride + g, a);
      _mm_storeu_ps(out + (p + 1) * stride + g, b);
      _mm_storeu_ps(out + (p + 2) * stride + g, c);
      _mm_storeu_ps(out + (p + 3) * stride + g, d);
    }
    for (; p < n; ++p) {
      float* dst = out + p * stride + g;
      dst[0] = r0[p];
      dst[1] = r1[p];
      dst[2] = r2[p];
      dst[3] = r3[p];
    }
  }
#endif
  for (; g < num_planes; ++g) {
    const float* src = planes + static_cast<size_t>(g) * n;
    for (size_t p = 0; p < n; ++p) out[p * stride + g] = src[p];
  }
}

}  // namespace casual3d::depth::sweep
