#pragma once

// Two doubles in one vector register: SSE2 natively, SIMD128 in WebAssembly,
// plain code elsewhere. Only operations whose result is fully specified by
// IEEE 754 (add, subtract, multiply, divide, square root, compare-and-select
// min and max, lane moves), so every build gives the same bits as the scalar
// expressions of the plain version below (f64x2_test.cc compares them).
// Internal to format/; used by the simplifier's block errors. The intrinsics
// headers come with the compiler.

#include <cmath>

#if defined(__wasm_simd128__)
#include <wasm_simd128.h>
#elif defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace casual3d {
namespace internal {

// The plain version: the reference for the vector ones, and the one used
// where neither instruction set is available.
namespace plain {
struct F64x2 {
  double v[2];
};
inline F64x2 LoadF64x2(const double* p) { return {{p[0], p[1]}}; }
inline F64x2 SplatF64x2(double x) { return {{x, x}}; }
inline F64x2 operator+(F64x2 a, F64x2 b) { return {{a.v[0] + b.v[0], a.v[1] + b.v[1]}}; }
inline F64x2 operator-(F64x2 a, F64x2 b) { return {{a.v[0] - b.v[0], a.v[1] - b.v[1]}}; }
inline F64x2 operator*(F64x2 a, F64x2 b) { return {{a.v[0] * b.v[0], a.v[1] * b.v[1]}}; }
inline F64x2 operator/(F64x2 a, F64x2 b) { return {{a.v[0] / b.v[0], a.v[1] / b.v[1]}}; }
inline F64x2 SqrtF64x2(F64x2 a) { return {{std::sqrt(a.v[0]), std::sqrt(a.v[1])}}; }
// Per lane t < lo ? t : lo, which is std::min(lo, t).
inline F64x2 MinF64x2(F64x2 lo, F64x2 t) {
  return {{t.v[0] < lo.v[0] ? t.v[0] : lo.v[0], t.v[1] < lo.v[1] ? t.v[1] : lo.v[1]}};
}
// Per lane hi < t ? t : hi, which is std::max(hi, t).
inline F64x2 MaxF64x2(F64x2 hi, F64x2 t) {
  return {{hi.v[0] < t.v[0] ? t.v[0] : hi.v[0], hi.v[1] < t.v[1] ? t.v[1] : hi.v[1]}};
}
// (a0, b0) and (a1, b1).
inline F64x2 UnpackLo(F64x2 a, F64x2 b) { return {{a.v[0], b.v[0]}}; }
inline F64x2 UnpackHi(F64x2 a, F64x2 b) { return {{a.v[1], b.v[1]}}; }
inline double Lane0(F64x2 a) { return a.v[0]; }
inline double Lane1(F64x2 a) { return a.v[1]; }
}  // namespace plain

#if defined(__wasm_simd128__)
struct F64x2 {
  v128_t v;
};
inline F64x2 LoadF64x2(const double* p) { return {wasm_v128_load(p)}; }
inline F64x2 SplatF64x2(double x) { return {wasm_f64x2_splat(x)}; }
inline F64x2 operator+(F64x2 a, F64x2 b) { return {wasm_f64x2_add(a.v, b.v)}; }
inline F64x2 operator-(F64x2 a, F64x2 b) { return {wasm_f64x2_sub(a.v, b.v)}; }
inline F64x2 operator*(F64x2 a, F64x2 b) { return {wasm_f64x2_mul(a.v, b.v)}; }
inline F64x2 operator/(F64x2 a, F64x2 b) { return {wasm_f64x2_div(a.v, b.v)}; }
inline F64x2 SqrtF64x2(F64x2 a) { return {wasm_f64x2_sqrt(a.v)}; }
// pmin(a, b) is b < a ? b : a, pmax(a, b) is a < b ? b : a.
inline F64x2 MinF64x2(F64x2 lo, F64x2 t) { return {wasm_f64x2_pmin(lo.v, t.v)}; }
inline F64x2 MaxF64x2(F64x2 hi, F64x2 t) { return {wasm_f64x2_pmax(hi.v, t.v)}; }
inline F64x2 UnpackLo(F64x2 a, F64x2 b) { return {wasm_i64x2_shuffle(a.v, b.v, 0, 2)}; }
inline F64x2 UnpackHi(F64x2 a, F64x2 b) { return {wasm_i64x2_shuffle(a.v, b.v, 1, 3)}; }
inline double Lane0(F64x2 a) { return wasm_f64x2_extract_lane(a.v, 0); }
inline double Lane1(F64x2 a) { return wasm_f64x2_extract_lane(a.v, 1); }
#elif defined(__SSE2__)
struct F64x2 {
  __m128d v;
};
inline F64x2 LoadF64x2(const double* p) { return {_mm_loadu_pd(p)}; }
inline F64x2 SplatF64x2(double x) { return {_mm_set1_pd(x)}; }
inline F64x2 operator+(F64x2 a, F64x2 b) { return {_mm_add_pd(a.v, b.v)}; }
inline F64x2 operator-(F64x2 a, F64x2 b) { return {_mm_sub_pd(a.v, b.v)}; }
inline F64x2 operator*(F64x2 a, F64x2 b) { return {_mm_mul_pd(a.v, b.v)}; }
inline F64x2 operator/(F64x2 a, F64x2 b) { return {_mm_div_pd(a.v, b.v)}; }
inline F64x2 SqrtF64x2(F64x2 a) { return {_mm_sqrt_pd(a.v)}; }
// minpd(a, b) is a < b ? a : b, maxpd(a, b) is a > b ? a : b.
inline F64x2 MinF64x2(F64x2 lo, F64x2 t) { return {_mm_min_pd(t.v, lo.v)}; }
inline F64x2 MaxF64x2(F64x2 hi, F64x2 t) { return {_mm_max_pd(t.v, hi.v)}; }
inline F64x2 UnpackLo(F64x2 a, F64x2 b) { return {_mm_unpacklo_pd(a.v, b.v)}; }
inline F64x2 UnpackHi(F64x2 a, F64x2 b) { return {_mm_unpackhi_pd(a.v, b.v)}; }
inline double Lane0(F64x2 a) { return _mm_cvtsd_f64(a.v); }
inline double Lane1(F64x2 a) { return _mm_cvtsd_f64(_mm_unpackhi_pd(a.v, a.v)); }
#else
using plain::F64x2;
using plain::LoadF64x2;
using plain::SplatF64x2;
using plain::operator+;
using plain::operator-;
using plain::operator*;
using plain::operator/;
using plain::SqrtF64x2;
using plain::MinF64x2;
using plain::MaxF64x2;
using plain::UnpackLo;
using plain::UnpackHi;
using plain::Lane0;
using plain::Lane1;
#endif

}  // namespace internal
}  // namespace casual3d
