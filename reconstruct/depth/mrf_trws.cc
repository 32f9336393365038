#include "reconstruct/depth/mrf_trws.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "reconstruct/depth/avx2_clones.h"
#include "reconstruct/depth/huge_pages.h"

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__ELF__)
#include <immintrin.h>
#define CASUAL3D_AVX2_MESSAGES 1
#endif

// The solver has an AVX2 version (avx2_clones.h): the belief and labelling
// loops run on eight labels at a time where the CPU has AVX2.

namespace casual3d::depth {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Labels rounded up to whole blocks of 8: every per-label array below has
// this stride; the distance transform treats labels past num_labels as +inf.
int PaddedLabels(int num_labels) { return (num_labels + 7) & ~7; }

// Messages from one node along kCount edges at once (kCount independent
// dependency chains keep the pipeline busy). For edge e, with
// h(l) = gamma * belief(l) - edge_e(l) for l < num_labels (the edge holding
// the message towards the node) and +inf above, the edge is overwritten with
//   m(l') = min_l h(l) + w_e * min(|l - l'|, T) - min_l h(l)
// by the lower-envelope distance transform of Felzenszwalb and Huttenlocher
// (2006): a forward and a backward min-plus recursion, then the truncation
// as a cap. Requires w_e >= 0.
#if defined(__SSE2__)
// The ramps (1, 2, 3, 4) w and (4, 3, 2, 1) w over a vector's lanes: the
// terms that reach a block's lanes from the carry before it (forward pass)
// or after it (backward pass).
inline __m128 RampUp(float w) { return _mm_set_ps(4.0f * w, 3.0f * w, 2.0f * w, w); }
inline __m128 RampDown(float w) { return _mm_set_ps(w, 2.0f * w, 3.0f * w, 4.0f * w); }
#endif

template <int kCount>
void SendMessages(const float* belief, float gamma, int num_labels, int padded, float* const* edges,
                  const float* weights, int truncation) {
#if defined(__SSE2__)
  // The recursions run on blocks of 8 labels: within a 4-label vector two
  // shift-and-min steps (offsets 1 and 2) give the recursion restricted to
  // the vector (lanes that would shift in from outside shift in themselves:
  // min(v, v + k w) = v for w >= 0); the second vector takes the first's
  // end; the carry from the previous block, plus w times the distance,
  // completes both. Only the carry is a loop-carried dependency.
  const __m128 g = _mm_set1_ps(gamma);
  const __m128 inf = _mm_set1_ps(kInf);
  // Per edge: w, 4w and the ramps (1..4) w and (4..1) w; other multiples are
  // derived where needed (fewer live registers).
  __m128 w1[kCount], w4[kCount], up[kCount], down[kCount], carry[kCount], hmin[kCount];
  for (int e = 0; e < kCount; ++e) {
    const float w = weights[e];
    w1[e] = _mm_set1_ps(w);
    w4[e] = _mm_set1_ps(4.0f * w);
    up[e] = RampUp(w);
    down[e] = RampDown(w);
    carry[e] = inf;
    hmin[e] = inf;
  }
  // h for labels [b, b + 4): +inf past num_labels.
  auto load_h = [&](int e, int b) {
    const __m128 v =
        _mm_sub_ps(_mm_mul_ps(g, _mm_loadu_ps(belief + b)), _mm_loadu_ps(edges[e] + b));
    if (b + 4 <= num_labels) return v;
    alignas(16) float lanes[4];
    _mm_store_ps(lanes, v);
    for (int l = std::max(0, num_labels - b); l < 4; ++l) lanes[l] = kInf;
    return _mm_load_ps(lanes);
  };
  for (int b = 0; b < padded; b += 8) {
    for (int e = 0; e < kCount; ++e) {
      __m128 a = load_h(e, b), c = load_h(e, b + 4);
      hmin[e] = _mm_min_ps(hmin[e], _mm_min_ps(a, c));
      a = _mm_min_ps(a, _mm_add_ps(_mm_shuffle_ps(a, a, _MM_SHUFFLE(2, 1, 0, 0)), w1[e]));
      c = _mm_min_ps(c, _mm_add_ps(_mm_shuffle_ps(c, c, _MM_SHUFFLE(2, 1, 0, 0)), w1[e]));
      const __m128 w2 = _mm_add_ps(w1[e], w1[e]);
      a = _mm_min_ps(a, _mm_add_ps(_mm_shuffle_ps(a, a, _MM_SHUFFLE(1, 0, 1, 0)), w2));
      c = _mm_min_ps(c, _mm_add_ps(_mm_shuffle_ps(c, c, _MM_SHUFFLE(1, 0, 1, 0)), w2));
      c = _mm_min_ps(c, _mm_add_ps(_mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 3, 3, 3)), up[e]));
      const __m128 base = _mm_add_ps(carry[e], up[e]);
      _mm_storeu_ps(edges[e] + b, _mm_min_ps(a, base));
      _mm_storeu_ps(edges[e] + b + 4, _mm_min_ps(c, _mm_add_ps(base, w4[e])));
      carry[e] = _mm_min_ps(_mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 3, 3)),
                            _mm_add_ps(carry[e], _mm_add_ps(w4[e], w4[e])));
    }
  }
  __m128 cap[kCount];
  for (int e = 0; e < kCount; ++e) {
    __m128 m = hmin[e];
    m = _mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
    hmin[e] = _mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1)));
    cap[e] = _mm_add_ps(hmin[e], _mm_set1_ps(weights[e] * static_cast<float>(truncation)));
    carry[e] = inf;
  }
  for (int b = padded - 8; b >= 0; b -= 8) {
    for (int e = 0; e < kCount; ++e) {
      __m128 a = _mm_loadu_ps(edges[e] + b), c = _mm_loadu_ps(edges[e] + b + 4);
      a = _mm_min_ps(a, _mm_add_ps(_mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 3, 2, 1)), w1[e]));
      c = _mm_min_ps(c, _mm_add_ps(_mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 2, 1)), w1[e]));
      const __m128 w2 = _mm_add_ps(w1[e], w1[e]);
      a = _mm_min_ps(a, _mm_add_ps(_mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 2, 3, 2)), w2));
      c = _mm_min_ps(c, _mm_add_ps(_mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 2, 3, 2)), w2));
      a = _mm_min_ps(a, _mm_add_ps(_mm_shuffle_ps(c, c, _MM_SHUFFLE(0, 0, 0, 0)), down[e]));
      const __m128 base = _mm_add_ps(carry[e], down[e]);
      const __m128 a_out = _mm_min_ps(a, _mm_add_ps(base, w4[e]));
      const __m128 c_out = _mm_min_ps(c, base);
      carry[e] = _mm_min_ps(_mm_shuffle_ps(a, a, _MM_SHUFFLE(0, 0, 0, 0)),
                            _mm_add_ps(carry[e], _mm_add_ps(w4[e], w4[e])));
      _mm_storeu_ps(edges[e] + b, _mm_sub_ps(_mm_min_ps(a_out, cap[e]), hmin[e]));
      _mm_storeu_ps(edges[e] + b + 4, _mm_sub_ps(_mm_min_ps(c_out, cap[e]), hmin[e]));
    }
  }
#else
  std::vector<float> h(padded);
  for (int e = 0; e < kCount; ++e) {
    float* out = edges[e];
    const float w = weights[e];
    for (int l = 0; l < padded; ++l) h[l] = l < num_labels ? gamma * belief[l] - out[l] : kInf;
    float hmin = h[0];
    out[0] = h[0];
    for (int l = 1; l < padded; ++l) {
      out[l] = std::min(h[l], out[l - 1] + w);
      hmin = std::min(hmin, h[l]);
    }
    for (int l = padded - 2; l >= 0; --l) out[l] = std::min(out[l], out[l + 1] + w);
    const float cap = hmin + w * static_cast<float>(truncation);
    for (int l = 0; l < padded; ++l) out[l] = std::min(out[l], cap) - hmin;
  }
#endif
}

// Asks for the cache lines of `bytes` bytes from ptr (a node's unary or
// message, about 14 lines each at 220 float labels) ahead of their use: a
// pass streams through over a gigabyte at the working resolution.
inline void Prefetch(const void* ptr, size_t bytes) {
#if defined(__GNUC__)
  for (size_t i = 0; i < bytes; i += 64) __builtin_prefetch(static_cast<const char*>(ptr) + i);
#endif
}

#if defined(CASUAL3D_AVX2_MESSAGES)
// SendMessages with AVX2 where the CPU has it: each block's two 4-label
// vectors are the two halves of one 8-label vector. The in-lane shuffles
// act on both halves as the SSE2 code's on each vector, and the steps that
// cross between the halves (the first half's last label into the second,
// the carries) add the same terms in the same order, so every message is
// bit-identical to SendMessages' (tested).
template <int kCount>
__attribute__((target("avx2"))) void SendMessagesAvx2(const float* belief, float gamma, int num_labels,
                                                     int padded, float* const* edges, const float* weights,
                                                     int truncation) {
  const __m256 g = _mm256_set1_ps(gamma);
  const __m256 inf8 = _mm256_set1_ps(kInf);
  const __m256i lane3 = _mm256_set1_epi32(3), lane4 = _mm256_set1_epi32(4);
  __m256 w1[kCount], up_hi[kCount], down_lo[kCount], hmin[kCount];
  __m128 w4[kCount], up[kCount], down[kCount], carry[kCount];
  for (int e = 0; e < kCount; ++e) {
    const float w = weights[e];
    w1[e] = _mm256_set1_ps(w);
    w4[e] = _mm_set1_ps(4.0f * w);
    up[e] = RampUp(w);
    down[e] = RampDown(w);
    // The ramps in the upper (lower) half, +inf in the other.
    up_hi[e] = _mm256_insertf128_ps(inf8, up[e], 1);
    down_lo[e] = _mm256_insertf128_ps(inf8, down[e], 0);
    carry[e] = _mm_set1_ps(kInf);
    hmin[e] = inf8;
  }
  for (int b = 0; b < padded; b += 8) {
    for (int e = 0; e < kCount; ++e) {
      // h for labels [b, b + 8): +inf past num_labels.
      __m256 x = _mm256_sub_ps(_mm256_mul_ps(g, _mm256_loadu_ps(belief + b)), _mm256_loadu_ps(edges[e] + b));
      if (b + 8 > num_labels) {
        alignas(32) float lanes[8];
        _mm256_store_ps(lanes, x);
        for (int l = std::max(0, num_labels - b); l < 8; ++l) lanes[l] = kInf;
        x = _mm256_load_ps(lanes);
      }
      hmin[e] = _mm256_min_ps(hmin[e], x);
      x = _mm256_min_ps(x, _mm256_add_ps(_mm256_shuffle_ps(x, x, _MM_SHUFFLE(2, 1, 0, 0)), w1[e]));
      const __m256 w2 = _mm256_add_ps(w1[e], w1[e]);
      x = _mm256_min_ps(x, _mm256_add_ps(_mm256_shuffle_ps(x, x, _MM_SHUFFLE(1, 0, 1, 0)), w2));
      x = _mm256_min_ps(x, _mm256_add_ps(_mm256_permutevar8x32_ps(x, lane3), up_hi[e]));
      const __m128 base = _mm_add_ps(carry[e], up[e]);
      const __m256 base8 = _mm256_insertf128_ps(_mm256_castps128_ps256(base), _mm_add_ps(base, w4[e]), 1);
      _mm256_storeu_ps(edges[e] + b, _mm256_min_ps(x, base8));
      const __m128 c = _mm256_extractf128_ps(x, 1);
      carry[e] = _mm_min_ps(_mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 3, 3)),
                            _mm_add_ps(carry[e], _mm_add_ps(w4[e], w4[e])));
    }
  }
  __m256 cap[kCount], hmin8[kCount];
  for (int e = 0; e < kCount; ++e) {
    __m128 m = _mm_min_ps(_mm256_castps256_ps128(hmin[e]), _mm256_extractf128_ps(hmin[e], 1));
    m = _mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
    m = _mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1)));
    hmin8[e] = _mm256_set1_ps(_mm_cvtss_f32(m));
    cap[e] = _mm256_add_ps(hmin8[e], _mm256_set1_ps(weights[e] * static_cast<float>(truncation)));
    carry[e] = _mm_set1_ps(kInf);
  }
  for (int b = padded - 8; b >= 0; b -= 8) {
    for (int e = 0; e < kCount; ++e) {
      __m256 x = _mm256_loadu_ps(edges[e] + b);
      x = _mm256_min_ps(x, _mm256_add_ps(_mm256_shuffle_ps(x, x, _MM_SHUFFLE(3, 3, 2, 1)), w1[e]));
      const __m256 w2 = _mm256_add_ps(w1[e], w1[e]);
      x = _mm256_min_ps(x, _mm256_add_ps(_mm256_shuffle_ps(x, x, _MM_SHUFFLE(3, 2, 3, 2)), w2));
      x = _mm256_min_ps(x, _mm256_add_ps(_mm256_permutevar8x32_ps(x, lane4), down_lo[e]));
      const __m128 base = _mm_add_ps(carry[e], down[e]);
      const __m256 base8 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_add_ps(base, w4[e])), base, 1);
      const __m256 out = _mm256_min_ps(x, base8);
      const __m128 a = _mm256_castps256_ps128(x);
      carry[e] = _mm_min_ps(_mm_shuffle_ps(a, a, _MM_SHUFFLE(0, 0, 0, 0)),
                            _mm_add_ps(carry[e], _mm_add_ps(w4[e], w4[e])));
      _mm256_storeu_ps(edges[e] + b, _mm256_sub_ps(_mm256_min_ps(out, cap[e]), hmin8[e]));
    }
  }
}
#endif

inline float Pairwise(float w, int a, int b, int truncation) {
  return w * static_cast<float>(std::min(std::abs(a - b), truncation));
}

// Index of the first minimum of c[0, n) (n a multiple of 4).
int ArgMin(const float* c, int n) {
#if defined(__SSE2__)
  __m128 m = _mm_loadu_ps(c);
  for (int l = 4; l < n; l += 4) m = _mm_min_ps(m, _mm_loadu_ps(c + l));
  m = _mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
  m = _mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1)));
  for (int l = 0; l < n; l += 4) {
    const int mask = _mm_movemask_ps(_mm_cmpeq_ps(_mm_loadu_ps(c + l), m));
    if (mask != 0) return l + __builtin_ctz(static_cast<unsigned>(mask));
  }
  return 0;
#else
  int best = 0;
  for (int l = 1; l < n; ++l)
    if (c[l] < c[best]) best = l;
  return best;
#endif
}

}  // namespace

double MrfEnergy(const GridMrf& mrf, const std::vector<uint16_t>& labels) {
  const int w = mrf.width, h = mrf.height, L = mrf.num_labels;
  double e = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      e += mrf.unary[p * L + labels[p]];
      if (x + 1 < w) e += Pairwise(mrf.weight_right[p], labels[p], labels[p + 1], mrf.truncation);
      if (y + 1 < h) e += Pairwise(mrf.weight_down[p], labels[p], labels[p + w], mrf.truncation);
    }
  return e;
}

size_t TrwsMessageBytes(int width, int height, int num_labels, bool half) {
  return 2 * static_cast<size_t>(width) * height * PaddedLabels(num_labels) * (half ? 2 : 4);
}

namespace {

#if defined(CASUAL3D_AVX2_MESSAGES)
// IEEE half <-> float for a message of n labels (n a multiple of 8), F16C.
__attribute__((target("avx2,f16c"), noinline)) void HalfToFloat(const uint16_t* src, float* dst, int n) {
  for (int i = 0; i < n; i += 8)
    _mm256_storeu_ps(dst + i, _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(src + i))));
}
__attribute__((target("avx2,f16c"), noinline)) void FloatToHalf(const float* src, uint16_t* dst, int n) {
  for (int i = 0; i < n; i += 8)
    _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + i),
                     _mm256_cvtps_ph(_mm256_loadu_ps(src + i), _MM_FROUND_TO_NEAREST_INT));
}
#endif

// Where the messages live. The passes work on float messages of S labels:
// with float storage these are the stored messages themselves; with half
// storage (Msg = uint16_t) a message is converted into a scratch buffer on
// Open and back on Close.
template <typename Msg>
struct MessageStore {
  Msg* base = nullptr;
  int stride = 0;
  float* Open(size_t p, float* /*scratch*/) const { return base + p * stride; }
  void Close(size_t /*p*/, const float* /*scratch*/) const {}
};

#if defined(CASUAL3D_AVX2_MESSAGES)
template <>
struct MessageStore<uint16_t> {
  uint16_t* base = nullptr;
  int stride = 0;
  float* Open(size_t p, float* scratch) const {
    HalfToFloat(base + p * stride, scratch, stride);
    return scratch;
  }
  void Close(size_t p, const float* scratch) const { FloatToHalf(scratch, base + p * stride, stride); }
};
#endif

// The solver, for either message storage; `avx2` selects the AVX2 distance
// transform.
template <typename Msg>
__attribute__((always_inline)) inline TrwsResult SolveTrwsWith(const GridMrf& mrf, const TrwsOptions& options,
                                                                BufferPool* pool, [[maybe_unused]] bool avx2) {
  const int w = mrf.width, h = mrf.height, L = mrf.num_labels;
  const size_t n = static_cast<size_t>(w) * h;
  // One message per edge (as in Kolmogorov 2006): at any time the edge
  // holds the message towards the endpoint that the current pass reaches
  // last, which is the only direction still needed. horizontal[p] is the edge
  // (x, y)-(x+1, y), vertical[p] the edge (x, y)-(x, y+1). Half the memory of
  // storing both directions, and the same results.
  const int S = PaddedLabels(L);
  // The pool hands out float buffers: half messages take half as many.
  const size_t floats = n * S * sizeof(Msg) / sizeof(float);
  std::vector<float> horizontal, vertical;
  TakeBuffer(pool, &horizontal, floats);
  TakeBuffer(pool, &vertical, floats);
  const MessageStore<Msg> hor{reinterpret_cast<Msg*>(horizontal.data()), S};
  const MessageStore<Msg> ver{reinterpret_cast<Msg*>(vertical.data()), S};
  // Scratch for the four messages at a node (used with half storage).
  std::vector<float> scratch(4 * static_cast<size_t>(S));
  float* const s_left = scratch.data();
  float* const s_right = s_left + S;
  float* const s_up = s_right + S;
  float* const s_down = s_up + S;
  const std::vector<float> zeros(S, 0.0f);
  std::vector<float> belief(S, 0.0f), cost(S, kInf);
  std::vector<float> label_f(S);
  for (int l = 0; l < S; ++l) label_f[l] = static_cast<float>(l);
  std::vector<uint16_t> labels(n, 0);
  TrwsResult result;
  result.energy = std::numeric_limits<double>::infinity();
  const int T = mrf.truncation;
  const float t_f = static_cast<float>(T);
  double prev_best = result.energy;
  int stale = 0;

  // Belief of node p: its unary plus the four incoming messages (missing
  // neighbours contribute `zeros`).
  auto compute_belief = [&](size_t p, const float* ml, const float* mr, const float* mu,
                            const float* md) {
    const float* __restrict u = &mrf.unary[p * L];
    float* __restrict b = belief.data();
    for (int l = 0; l < L; ++l) b[l] = u[l] + ml[l] + mr[l] + mu[l] + md[l];
  };
  // Messages from the node whose belief is in `belief` along one or two
  // edges (each holding the message towards the node; overwritten).
  auto send = [&](float gamma, float* e0, float w0, float* e1, float w1) {
    if (e0 && e1) {
      float* const edges[2] = {e0, e1};
      const float weights[2] = {w0, w1};
#if defined(CASUAL3D_AVX2_MESSAGES)
      if (avx2) return SendMessagesAvx2<2>(belief.data(), gamma, L, S, edges, weights, T);
#endif
      SendMessages<2>(belief.data(), gamma, L, S, edges, weights, T);
    } else if (e0 || e1) {
      float* const edges[1] = {e0 ? e0 : e1};
      const float weights[1] = {e0 ? w0 : w1};
#if defined(CASUAL3D_AVX2_MESSAGES)
      if (avx2) return SendMessagesAvx2<1>(belief.data(), gamma, L, S, edges, weights, T);
#endif
      SendMessages<1>(belief.data(), gamma, L, S, edges, weights, T);
    }
  };

  // Prefetching: node q's unary and the messages a pass reads at q (its own
  // edges, and the edge from the node above when q has one).
  const size_t kAhead = 2;  // Nodes ahead.
  const size_t msg_bytes = S * sizeof(Msg);
  auto prefetch_node = [&](size_t q) {
    Prefetch(&mrf.unary[q * L], L * sizeof(float));
    Prefetch(hor.base + q * S, msg_bytes);
    Prefetch(ver.base + q * S, msg_bytes);
    if (q >= static_cast<size_t>(w)) Prefetch(ver.base + (q - w) * S, msg_bytes);
  };
  for (int iter = 0; iter < options.max_iterations; ++iter) {
    // Forward pass (raster order): messages to the right and down neighbours,
    // and the labelling conditioned on the already labelled left/up nodes.
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const size_t p = static_cast<size_t>(y) * w + x;
        float* mr = hor.Open(p, s_right);
        float* md = ver.Open(p, s_down);
        const float* ml = x > 0 ? hor.Open(p - 1, s_left) : zeros.data();
        const float* mu = y > 0 ? ver.Open(p - w, s_up) : zeros.data();
        if (p + kAhead < n) prefetch_node(p + kAhead);
        // Belief, and the labelling cost (Kolmogorov 2006, Sec. 5): unary,
        // messages from the nodes not yet labelled in this pass, and the
        // pairwise terms to the labelled left and up neighbours.
        {
          const float* __restrict u = &mrf.unary[p * L];
          const float* __restrict lf = label_f.data();
          float* __restrict b = belief.data();
          float* __restrict c = cost.data();
          const float ll = x > 0 ? static_cast<float>(labels[p - 1]) : 0.0f;
          const float lu = y > 0 ? static_cast<float>(labels[p - w]) : 0.0f;
          const float wl = x > 0 ? mrf.weight_right[p - 1] : 0.0f;
          const float wu = y > 0 ? mrf.weight_down[p - w] : 0.0f;
          // Two loops, not one: with six inputs and two outputs the
          // vectoriser gives up on its runtime overlap checks and the loop
          // stays scalar (three times the time of the pass's other work).
          for (int l = 0; l < L; ++l) b[l] = u[l] + ml[l] + mr[l] + mu[l] + md[l];
          for (int l = 0; l < L; ++l) {
            const float pl = wl * std::min(std::abs(lf[l] - ll), t_f);
            const float pu = wu * std::min(std::abs(lf[l] - lu), t_f);
            c[l] = u[l] + mr[l] + md[l] + pl + pu;
          }
          labels[p] = static_cast<uint16_t>(ArgMin(cost.data(), S));
        }
        const int before = (x > 0) + (y > 0), after = (x + 1 < w) + (y + 1 < h);
        const float gamma = 1.0f / static_cast<float>(std::max(1, std::max(before, after)));
        send(gamma, x + 1 < w ? mr : nullptr, mrf.weight_right[p], y + 1 < h ? md : nullptr,
             mrf.weight_down[p]);
        if (x + 1 < w) hor.Close(p, mr);
        if (y + 1 < h) ver.Close(p, md);
      }
    }
    const double e = MrfEnergy(mrf, labels);
    if (e < result.energy) {
      result.energy = e;
      result.labels = labels;
    }
    result.pass_energies.push_back(e);
    result.iterations = iter + 1;
    // Backward pass (reverse raster order): messages to the left and up neighbours.
    for (int y = h - 1; y >= 0; --y) {
      for (int x = w - 1; x >= 0; --x) {
        const size_t p = static_cast<size_t>(y) * w + x;
        float* ml = x > 0 ? hor.Open(p - 1, s_left) : nullptr;
        float* mu = y > 0 ? ver.Open(p - w, s_up) : nullptr;
        const float* mr = x + 1 < w ? hor.Open(p, s_right) : zeros.data();
        const float* md = y + 1 < h ? ver.Open(p, s_down) : zeros.data();
        if (p >= kAhead) prefetch_node(p - kAhead);
        compute_belief(p, ml ? ml : zeros.data(), mr, mu ? mu : zeros.data(), md);
        const int before = (x > 0) + (y > 0), after = (x + 1 < w) + (y + 1 < h);
        const float gamma = 1.0f / static_cast<float>(std::max(1, std::max(before, after)));
        send(gamma, ml, x > 0 ? mrf.weight_right[p - 1] : 0.0f, mu,
             y > 0 ? mrf.weight_down[p - w] : 0.0f);
        if (ml) hor.Close(p - 1, ml);
        if (mu) ver.Close(p - w, mu);
      }
    }
    // Stop after `patience` passes without a significant improvement.
    if (prev_best - result.energy <= options.relative_tolerance * std::abs(result.energy)) {
      if (++stale >= options.patience) break;
    } else {
      stale = 0;
      prev_best = result.energy;
    }
  }
  if (pool) {
    pool->Give(&horizontal);
    pool->Give(&vertical);
  }
  return result;
}

CASUAL3D_AVX2_CLONES
TrwsResult SolveTrwsFloat(const GridMrf& mrf, const TrwsOptions& options, BufferPool* pool, bool avx2) {
  return SolveTrwsWith<float>(mrf, options, pool, avx2);
}

#if defined(CASUAL3D_AVX2_MESSAGES)
__attribute__((target("avx2,f16c"))) TrwsResult SolveTrwsHalf(const GridMrf& mrf, const TrwsOptions& options,
                                                              BufferPool* pool) {
  return SolveTrwsWith<uint16_t>(mrf, options, pool, true);
}
#endif

}  // namespace

bool TrwsHalfMessagesAvailable() {
#if defined(CASUAL3D_AVX2_MESSAGES)
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("f16c");
#else
  return false;
#endif
}

TrwsResult SolveTrws(const GridMrf& mrf, const TrwsOptions& options, BufferPool* pool) {
  const int w = mrf.width, h = mrf.height, L = mrf.num_labels;
  const size_t n = static_cast<size_t>(w) * h;
  if (w <= 0 || h <= 0 || L < 1 || L > 65535 || mrf.unary.size() != n * L ||
      mrf.weight_right.size() != n || mrf.weight_down.size() != n || mrf.truncation < 1)
    throw std::invalid_argument("TRW-S: inconsistent MRF sizes");
  if (options.max_iterations < 1) throw std::invalid_argument("TRW-S: max_iterations < 1");
  for (size_t p = 0; p < n; ++p)
    if (!(mrf.weight_right[p] >= 0.0f && mrf.weight_down[p] >= 0.0f))
      throw std::invalid_argument("TRW-S: edge weight of pixel " + std::to_string(p) +
                                  " is negative or NaN");
#if defined(CASUAL3D_AVX2_MESSAGES)
  if (options.half_messages && TrwsHalfMessagesAvailable()) return SolveTrwsHalf(mrf, options, pool);
  return SolveTrwsFloat(mrf, options, pool, options.avx2_messages && __builtin_cpu_supports("avx2"));
#else
  return SolveTrwsFloat(mrf, options, pool, false);
#endif
}

}  // namespace casual3d::depth
