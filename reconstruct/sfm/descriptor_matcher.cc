#include "reconstruct/sfm/descriptor_matcher.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

#include "base/parallel_for.h"

// On x86-64 the tile kernel is compiled twice, for AVX2 + FMA (eight lanes)
// and for the baseline (four lanes), and the first call picks one by the
// CPU's features. Every dot product is an exact integer in float, so both
// give the same bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define CASUAL3D_MATCHER_AVX2 1
#endif

namespace casual3d::sfm {
namespace {

constexpr int kD = kSiftDimensions;
constexpr int kRowBlock = 4;   // Rows of A per tile.
constexpr int kColTile = 16;   // Columns (rows of B) per tile: two vectors of 8.

typedef float V8f __attribute__((vector_size(32)));
typedef int32_t V8i __attribute__((vector_size(32)));
typedef float V4f __attribute__((vector_size(16)));
typedef int32_t V4i __attribute__((vector_size(16)));

// Best two similarities of one feature and the index of the best (-1: none).
struct Best2 {
  float best = 0.0f;
  float second = 0.0f;
  int index = -1;
};

// A feature's match, or -1, from its best two similarities (COLMAP's rule).
int Accept(const Best2& b, const DescriptorMatchOptions& o) {
  if (b.index < 0) return -1;
  constexpr double kNorm = 1.0 / (512.0 * 512.0);
  const double best = std::acos(std::min(1.0, kNorm * b.best));
  if (best > o.max_distance) return -1;
  const double second = std::acos(std::min(1.0, kNorm * b.second));
  if (best >= o.max_ratio * second) return -1;
  return b.index;
}

// All lanes x (one broadcast).
template <typename V, typename VI>
__attribute__((always_inline)) inline void Splat(float x, V* out) {
  V v = V{};
  v[0] = x;
  *out = __builtin_shuffle(v, VI{});
}

// The best two similarities of every row of A (4 * row_blocks rows,
// row-major, 128 floats each) among the columns of B (cols of them, a
// multiple of 16, packed tile by tile: 16 columns x 128 values k-major, 8 KB
// contiguous, so a tile's loads never alias in the L1 cache), and of every
// column among the rows. Padding rows and
// columns are zero: their similarities (0) never change a result.
// V, VI: float and int vectors of W lanes; a tile is kColTile / W of them.
template <typename V, typename VI>
__attribute__((always_inline)) inline void BestTwoKernel(const float* a, int row_blocks,
                                                         const float* bt, int cols, Best2* row_out,
                                                         float* col_best, float* col_second,
                                                         int32_t* col_index) {
  constexpr int W = static_cast<int>(sizeof(V) / sizeof(float));
  constexpr int H = kColTile / W;
  VI lane;
  for (int l = 0; l < W; ++l) lane[l] = l;
  for (int j = 0; j < cols; ++j) {
    col_best[j] = 0.0f;
    col_second[j] = 0.0f;
    col_index[j] = -1;
  }
  for (int blk = 0; blk < row_blocks; ++blk) {
    const float* ab = a + static_cast<size_t>(blk) * kRowBlock * kD;
    // Per row, lane-wise best two over the columns seen so far.
    V rb[kRowBlock][H], rs[kRowBlock][H];
    VI ri[kRowBlock][H];
    for (int r = 0; r < kRowBlock; ++r)
      for (int h = 0; h < H; ++h) {
        rb[r][h] = V{};
        rs[r][h] = V{};
        ri[r][h] = VI{} - 1;
      }
    for (int j0 = 0; j0 < cols; j0 += kColTile) {
      V acc[kRowBlock][H];
      for (int r = 0; r < kRowBlock; ++r)
        for (int h = 0; h < H; ++h) acc[r][h] = V{};
      const float* bk = bt + static_cast<size_t>(j0) * kD;
      for (int k = 0; k < kD; ++k, bk += kColTile) {
        V b[H];
        for (int h = 0; h < H; ++h) std::memcpy(&b[h], bk + W * h, sizeof(V));
        for (int r = 0; r < kRowBlock; ++r) {
          V av;
          Splat<V, VI>(ab[r * kD + k], &av);
          for (int h = 0; h < H; ++h) acc[r][h] += av * b[h];
        }
      }
      for (int h = 0; h < H; ++h) {
        const VI jv = lane + (j0 + W * h);
        // Rows: strictly greater replaces the best, so ties keep the first.
        for (int r = 0; r < kRowBlock; ++r) {
          const V v = acc[r][h];
          const VI better = v > rb[r][h];
          const V lower = v < rb[r][h] ? v : rb[r][h];
          rs[r][h] = rs[r][h] > lower ? rs[r][h] : lower;
          rb[r][h] = better ? v : rb[r][h];
          ri[r][h] = better ? jv : ri[r][h];
        }
        // Columns: rows in increasing order, same rule.
        V cb, cs;
        VI ci;
        std::memcpy(&cb, col_best + j0 + W * h, sizeof(cb));
        std::memcpy(&cs, col_second + j0 + W * h, sizeof(cs));
        std::memcpy(&ci, col_index + j0 + W * h, sizeof(ci));
        for (int r = 0; r < kRowBlock; ++r) {
          const V v = acc[r][h];
          const VI better = v > cb;
          const V lower = v < cb ? v : cb;
          cs = cs > lower ? cs : lower;
          cb = better ? v : cb;
          ci = better ? (VI{} + (blk * kRowBlock + r)) : ci;
        }
        std::memcpy(col_best + j0 + W * h, &cb, sizeof(cb));
        std::memcpy(col_second + j0 + W * h, &cs, sizeof(cs));
        std::memcpy(col_index + j0 + W * h, &ci, sizeof(ci));
      }
    }
    // Merge each row's 16 lanes: the best value with its lowest index; the
    // second is the best of the seconds and of the other lanes' bests.
    for (int r = 0; r < kRowBlock; ++r) {
      Best2 out;
      int win = -1;
      for (int h = 0; h < H; ++h)
        for (int l = 0; l < W; ++l) {
          const float v = rb[r][h][l];
          const int idx = ri[r][h][l];
          if (idx < 0) continue;
          if (v > out.best || (v == out.best && out.index >= 0 && idx < out.index)) {
            out.best = v;
            out.index = idx;
            win = h * W + l;
          }
        }
      for (int h = 0; h < H; ++h)
        for (int l = 0; l < W; ++l) {
          out.second = std::max(out.second, rs[r][h][l]);
          if (h * W + l != win) out.second = std::max(out.second, rb[r][h][l]);
        }
      row_out[blk * kRowBlock + r] = out;
    }
  }
}

#ifdef CASUAL3D_MATCHER_AVX2
__attribute__((target("avx2,fma"))) void BestTwoAvx2(const float* a, int row_blocks,
                                                      const float* bt, int cols, Best2* row_out,
                                                      float* col_best, float* col_second,
                                                      int32_t* col_index) {
  BestTwoKernel<V8f, V8i>(a, row_blocks, bt, cols, row_out, col_best, col_second, col_index);
}
#endif

void BestTwoBothWays(const float* a, int row_blocks, const float* bt, int cols, Best2* row_out,
                     float* col_best, float* col_second, int32_t* col_index) {
#ifdef CASUAL3D_MATCHER_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (avx2) {
    BestTwoAvx2(a, row_blocks, bt, cols, row_out, col_best, col_second, col_index);
    return;
  }
#endif
  BestTwoKernel<V4f, V4i>(a, row_blocks, bt, cols, row_out, col_best, col_second, col_index);
}

void CheckDescriptors(const SiftDescriptors& d, const char* which) {
  if (d.rows < 0 || d.data.size() != static_cast<size_t>(d.rows) * kD)
    throw std::invalid_argument(std::string("descriptor matching: photo ") + which + " has " +
                                std::to_string(d.data.size()) + " bytes for " +
                                std::to_string(d.rows) + " descriptors of 128");
}

// Per-thread buffers for one pair.
struct Workspace {
  std::vector<float> a, bt, col_best, col_second;
  std::vector<int32_t> col_index;
  std::vector<Best2> rows;
};

FeatureMatches Match(const SiftDescriptors& a, const SiftDescriptors& b,
                     const DescriptorMatchOptions& o, Workspace* ws) {
  CheckDescriptors(a, "A");
  CheckDescriptors(b, "B");
  if (!(o.max_ratio > 0 && o.max_ratio <= 1))
    throw std::invalid_argument("descriptor matching: max_ratio outside (0, 1]");
  if (!(o.max_distance > 0 && o.max_distance <= M_PI / 2))
    throw std::invalid_argument("descriptor matching: max_distance outside (0, pi/2]");
  FeatureMatches matches;
  if (a.rows == 0 || b.rows == 0) return matches;
  const int blocks = (a.rows + kRowBlock - 1) / kRowBlock;
  const int cols = (b.rows + kColTile - 1) / kColTile * kColTile;
  ws->a.assign(static_cast<size_t>(blocks) * kRowBlock * kD, 0.0f);
  for (size_t i = 0; i < a.data.size(); ++i) ws->a[i] = a.data[i];
  ws->bt.assign(static_cast<size_t>(kD) * cols, 0.0f);
  for (int j = 0; j < b.rows; ++j) {
    const uint8_t* row = &b.data[static_cast<size_t>(j) * kD];
    float* tile = &ws->bt[static_cast<size_t>(j / kColTile) * kColTile * kD + j % kColTile];
    for (int k = 0; k < kD; ++k) tile[k * kColTile] = row[k];
  }
  ws->col_best.resize(cols);
  ws->col_second.resize(cols);
  ws->col_index.resize(cols);
  ws->rows.resize(static_cast<size_t>(blocks) * kRowBlock);
  BestTwoBothWays(ws->a.data(), blocks, ws->bt.data(), cols, ws->rows.data(), ws->col_best.data(),
                  ws->col_second.data(), ws->col_index.data());
  for (int i = 0; i < a.rows; ++i) {
    const int j = Accept(ws->rows[i], o);
    if (j < 0) continue;
    if (o.cross_check) {
      const Best2 back{ws->col_best[j], ws->col_second[j], ws->col_index[j]};
      if (Accept(back, o) != i) continue;
    }
    matches.emplace_back(static_cast<uint32_t>(i), static_cast<uint32_t>(j));
  }
  return matches;
}

}  // namespace

FeatureMatches MatchDescriptors(const SiftDescriptors& a, const SiftDescriptors& b,
                                const DescriptorMatchOptions& options) {
  Workspace ws;
  return Match(a, b, options, &ws);
}

std::vector<std::pair<int, int>> ExhaustivePairs(int n) {
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) pairs.emplace_back(i, j);
  return pairs;
}

std::vector<std::pair<int, int>> SequentialPairs(int n, int overlap) {
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < n; ++i) {
    std::vector<int> ahead;
    for (int k = 1; k < overlap && i + k < n; ++k) ahead.push_back(i + k);
    for (int k = 0; k < overlap && k < 31 && i + (int64_t{1} << k) < n; ++k)
      ahead.push_back(i + (1 << k));
    std::sort(ahead.begin(), ahead.end());
    ahead.erase(std::unique(ahead.begin(), ahead.end()), ahead.end());
    for (int j : ahead) pairs.emplace_back(i, j);
  }
  return pairs;
}

std::vector<FeatureMatches> MatchPairs(const std::vector<SiftDescriptors>& photos,
                                       const std::vector<std::pair<int, int>>& pairs,
                                       const DescriptorMatchOptions& options, int num_threads,
                                       const std::function<bool(int, int)>& on_pair) {
  const int n = static_cast<int>(photos.size());
  for (const auto& [i, j] : pairs)
    if (i < 0 || j < 0 || i >= n || j >= n || i == j)
      throw std::invalid_argument("descriptor matching: pair (" + std::to_string(i) + ", " +
                                  std::to_string(j) + ") outside the " + std::to_string(n) +
                                  " photos");
  std::vector<FeatureMatches> out(pairs.size());
  const int total = static_cast<int>(pairs.size());
  const int threads = std::max(1, std::min(base::ResolveThreads(num_threads), total));
  std::vector<Workspace> workspaces(threads);  // One per thread.
  std::mutex mutex;
  int done = 0;
  std::atomic<bool> cancelled(false);
  base::ParallelFor(0, total, threads, [&](int64_t k, int thread) {
    if (cancelled.load()) return;
    out[k] = Match(photos[pairs[k].first], photos[pairs[k].second], options, &workspaces[thread]);
    std::lock_guard<std::mutex> lock(mutex);
    ++done;
    if (on_pair && !on_pair(done, total)) cancelled.store(true);
  });
  return out;
}

}  // namespace casual3d::sfm
