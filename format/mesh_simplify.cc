#include "format/mesh_simplify.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "format/f64x2.h"
#include "format/parallel.h"

namespace casual3d {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Candidate error thresholds: max_relative_error * 2^(-i/4), i = 0..kNumSteps-1,
// then 0 (exactly planar blocks only). 2^(-1/4) rounded to double.
constexpr int kNumSteps = 80;
constexpr double kQuarterOctave = 0.84089641525371454303;

// Eight bytes from p as one word (any alignment).
inline uint64_t Load64(const uint8_t* p) {
  uint64_t v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
constexpr uint64_t kOnes = 0x0101010101010101ull;

// back_in_column[x] = 1 if pixel (x, y) or (x, y + 1) has a back node, for
// x = 0 .. w - 1, and back_in_column[w] = back_in_column[0]; the array holds
// at least w + 1 bytes.
inline void BackInColumns(const TwoLayerPanorama& p, int y, uint8_t* back_in_column) {
  const int w = p.width();
  const uint8_t* upper = &p.layer(kBack).present[p.index(0, y)];
  const uint8_t* lower = upper + w;
  int x = 0;
  for (; x + 8 <= w; x += 8) {
    const uint64_t v = Load64(upper + x) | Load64(lower + x);
    std::memcpy(back_in_column + x, &v, sizeof(v));
  }
  for (; x < w; ++x) back_in_column[x] = upper[x] | lower[x];
  back_in_column[w] = back_in_column[0];
}

// Pixel-centre direction tables, the same arithmetic as MeshAssembler::Finish.
struct Directions {
  std::vector<double> sin_lon, cos_lon, sin_lat, cos_lat;
  Directions(int w, int h) : sin_lon(w), cos_lon(w), sin_lat(h), cos_lat(h) {
    for (int x = 0; x < w; ++x) {
      DeterministicSinCos(((x + 0.5) / w - 0.5) * 2.0 * kPi, &sin_lon[x], &cos_lon[x]);
    }
    for (int y = 0; y < h; ++y) {
      DeterministicSinCos((0.5 - (y + 0.5) / h) * kPi, &sin_lat[y], &cos_lat[y]);
    }
  }
};

// The tile a thread is evaluating (its top-left quad) and its node positions
// (LayerPyramid::PrepareTile).
struct TileCache {
  int x0 = 0, y0 = 0;
  bool ready = false;
  std::vector<double> px, py, pz;
};

// The quadtree of one layer. Level 0 holds pixel quads (x, y) .. (x+1, y+1),
// level k blocks of 2^k x 2^k quads whose top-left quad is (bx 2^k, by 2^k);
// only blocks wholly inside the quad grid (width columns with wrap, height - 1
// rows) exist. error[k][by * nx[k] + bx] is the block's relative error, or
// infinity if it cannot be merged.
//
// Errors above `max_error` are stored as infinity: no threshold the
// simplifier tries exceeds it, so such a block behaves exactly like one that
// cannot be merged, and its parent need not look at its nodes.
//
// Cost: every node of a mergeable block enters one dot product per level, so
// the quad grid is walked in tiles of the largest block's size, all levels of
// one tile at a time, with the tile's node positions computed once and kept
// in a cache small enough for the processor's caches (400 KB for 128 quads).
class LayerPyramid {
 public:
  // Finds the full quads (FullQuads) and allocates the errors.
  // EvaluateTileRow then fills them, one row of tiles of the largest block
  // size at a time: rows are independent, so threads may take different rows.
  LayerPyramid(const TwoLayerPanorama& p, const Directions& dirs, int layer, int levels,
               double max_error, int num_threads)
      : p_(p), dirs_(dirs), layer_(layer), max_error_(max_error) {
    const int qw = p.width(), qh = p.height() - 1;
    tile_ = 1 << levels;
    FullQuads(num_threads);
    nx_.push_back(qw);
    ny_.push_back(qh);
    error_.emplace_back();  // Level 0 uses full_.
    for (int k = 1; k <= levels; ++k) {
      const int s = 1 << k;
      nx_.push_back(qw / s);
      ny_.push_back(qh / s);
      error_.emplace_back(static_cast<size_t>(nx_[k]) * ny_[k], kInf);
    }
  }

  // Rows of tiles of the largest block size.
  int num_tile_rows() const { return (nx_[0] > 0 ? ny_[0] + tile_ - 1 : 0) / tile_; }

  // The errors of every block in tile row `ty`. Blocks nest inside tiles, so
  // a block's children are evaluated before it; a tile without a full quad
  // has no mergeable block. `cache` is the calling thread's own.
  void EvaluateTileRow(int ty, TileCache* cache) {
    const int qw = nx_[0];
    const int tile = tile_;
    const int tiles_x = (qw + tile - 1) / tile;
    const int y0 = ty * tile;
    for (int x0 = 0; x0 < qw; x0 += tile) {
      if (!tile_has_full_[static_cast<size_t>(ty) * tiles_x + x0 / tile]) continue;
      cache->x0 = x0;
      cache->y0 = y0;
      cache->ready = false;
      for (int k = 1; k <= levels(); ++k) {
        const int s = 1 << k;
        const int by_end = std::min(ny_[k], (y0 + tile) / s);
        const int bx_end = std::min(nx_[k], (x0 + tile) / s);
        for (int by = y0 / s; by < by_end; ++by) {
          int bx = x0 / s;
          if (k == 1) bx = Level1Pairs(by, bx, bx_end, cache);
          for (; bx < bx_end; ++bx) {
            error_[k][Index(k, bx, by)] = BlockError(k, bx, by, cache);
          }
        }
      }
    }
  }

  // Frees what only EvaluateTileRow needs.
  void ReleaseScratch() { std::vector<uint8_t>().swap(tile_has_full_); }

  int levels() const { return static_cast<int>(error_.size()) - 1; }
  int nx(int k) const { return nx_[k]; }
  int ny(int k) const { return ny_[k]; }
  size_t Index(int k, int bx, int by) const { return static_cast<size_t>(by) * nx_[k] + bx; }
  double Error(int k, int bx, int by) const { return error_[k][Index(k, bx, by)]; }
  // Error(k, bx, by) for bx = 0 .. nx(k) - 1.
  // (data() + offset: a level may have rows but no columns, its vector empty.)
  const double* ErrorRow(int k, int by) const { return error_[k].data() + Index(k, 0, by); }
  // Whether pixel quad (x, y) has four nodes of this layer linked around it.
  bool FullQuad(int x, int y) const { return full_[static_cast<size_t>(y) * nx_[0] + x] != 0; }
  // FullQuad(x, y) for x = 0 .. width - 1 (1 or 0 per quad).
  const uint8_t* FullRow(int y) const { return &full_[static_cast<size_t>(y) * nx_[0]]; }

 private:
  // full_: whether all four corners of a quad are nodes of this layer, linked
  // to each other around the quad. Per node, bit 7: present; bit 2d: the link
  // in direction d leads to this layer. Byte-wise arithmetic without tables,
  // eight nodes per 64-bit word. Also notes which tiles of the largest block
  // size hold a full quad at all (tile_has_full_). Bands of one tile's rows
  // are independent and go to different threads.
  void FullQuads(int num_threads) {
    const int w = p_.width(), qh = p_.height() - 1;
    const int tile = tile_;
    const LayerData& d = p_.layer(layer_);
    const bool front = layer_ == kFront;
    // Rows of node bits, padded to whole 8-byte words plus one byte (column
    // w repeats column 0), processed 8 nodes at a time in 64-bit words.
    const size_t words = (static_cast<size_t>(w) + 1 + 7) / 8;
    auto row_bits = [&](int y, std::vector<uint8_t>* out) {
      const uint8_t* links = &d.links[p_.index(0, y)];
      const uint8_t* present = &d.present[p_.index(0, y)];
      uint8_t* o = out->data();
      int x = 0;
      for (; x + 8 <= w; x += 8) {
        const uint64_t L = Load64(links + x), P = Load64(present + x);
        const uint64_t lo = L & (0x55 * kOnes), hi = (L >> 1) & (0x55 * kOnes);
        const uint64_t same = front ? lo & ~hi : hi & ~lo;  // Link::kFront is 1, kBack 2.
        // Bit 7 of each byte: the byte of P is not zero.
        const uint64_t nonzero = ((P & (0x7f * kOnes)) + 0x7f * kOnes) | P;
        const uint64_t bits = same | (nonzero & (0x80 * kOnes));
        std::memcpy(o + x, &bits, sizeof(bits));
      }
      for (; x < w; ++x) {
        const unsigned lo = links[x] & 0x55u, hi = (links[x] >> 1) & 0x55u;
        const unsigned same = front ? lo & ~hi : hi & ~lo;
        o[x] = static_cast<uint8_t>(same | (present[x] != 0 ? 0x80u : 0u));
      }
      o[w] = o[0];
    };
    constexpr unsigned kP = 0x80, kR = 1u << (2 * kRight), kD = 1u << (2 * kDown),
                       kL = 1u << (2 * kLeft), kU = 1u << (2 * kUp);
    constexpr uint64_t kA = (kP | kR | kD) * kOnes, kB = (kP | kD | kL) * kOnes,
                       kC = (kP | kR | kU) * kOnes, kDD = (kP | kU | kL) * kOnes;
    full_.resize(static_cast<size_t>(w) * qh + 8);  // 8 bytes of slack for word loads.
    const int tiles_x = (w + tile - 1) / tile;
    const int tiles_y = (qh + tile - 1) / tile;
    tile_has_full_.assign(static_cast<size_t>(tiles_x) * tiles_y, 0);
    ParallelFor(0, tiles_y, num_threads, [&](int64_t ty) {
      std::vector<uint8_t> upper(8 * words + 8, 0), lower(8 * words + 8, 0);
      const int y_begin = static_cast<int>(ty) * tile;
      const int y_end = std::min(qh, y_begin + tile);
      row_bits(y_begin, &upper);
      uint8_t* has = &tile_has_full_[static_cast<size_t>(ty) * tiles_x];
      for (int y = y_begin; y < y_end; ++y) {
        row_bits(y + 1, &lower);
        uint8_t* full = &full_[static_cast<size_t>(y) * w];
        const uint8_t* u = upper.data();
        const uint8_t* l = lower.data();
        // A quad is full when no required bit is missing at any of its
        // corners. The last word of a row is stored only up to column w - 1:
        // the next row may belong to another thread.
        for (int x = 0; x < w; x += 8) {
          const uint64_t missing = (~Load64(u + x) & kA) | (~Load64(u + x + 1) & kB) |
                                   (~Load64(l + x) & kC) | (~Load64(l + x + 1) & kDD);
          const uint64_t any_missing = ((missing & (0x7f * kOnes)) + 0x7f * kOnes) | missing;
          const uint64_t bits = (~any_missing >> 7) & kOnes;
          std::memcpy(full + x, &bits, static_cast<size_t>(std::min(8, w - x)));
        }
        for (int tx = 0; tx < tiles_x; ++tx) {
          const int end = std::min(w, (tx + 1) * tile);
          uint64_t any = 0;
          int x = tx * tile;
          for (; x + 8 <= end; x += 8) any |= Load64(full + x);
          for (; x < end; ++x) any |= full[x];
          has[tx] |= any != 0 ? 1 : 0;
        }
        upper.swap(lower);
      }
    });
  }

  // Positions (x, y, z) of the nodes of the current tile: rows c->y0 ..
  // c->y0 + tile size and columns c->x0 .. c->x0 + tile size, clipped
  // to the grid (column `width` repeats column 0), computed on first use and
  // stored as three planes (px, py, pz) of (tile + 1)^2 doubles.
  void PrepareTile(TileCache* c) {
    if (c->ready) return;
    c->ready = true;
    const int w = p_.width(), last_row = p_.height() - 1;
    const int tile = tile_;
    const int rows = std::min(tile, last_row - c->y0) + 1;
    const int cols = std::min(tile, w - c->x0) + 1;
    const size_t stride = static_cast<size_t>(tile) + 1;
    // Two doubles of padding: Level1Pairs loads one past a row's last node.
    c->px.resize(stride * stride + 2);
    c->py.resize(stride * stride + 2);
    c->pz.resize(stride * stride + 2);
    const LayerData& d = p_.layer(layer_);
    // Columns c->x0 .. c->x0 + inner - 1 need no wrap.
    const int inner = std::min(cols, w - c->x0);
    const double* sin_lon = &dirs_.sin_lon[c->x0];
    const double* cos_lon = &dirs_.cos_lon[c->x0];
    for (int r = 0; r < rows; ++r) {
      const int y = c->y0 + r;
      const float* depth_row = &d.depth_m[p_.index(0, y)];
      const float* depth = depth_row + c->x0;
      const double cos_lat = dirs_.cos_lat[y], sin_lat = dirs_.sin_lat[y];
      double* ox = &c->px[r * stride];
      double* oy = &c->py[r * stride];
      double* oz = &c->pz[r * stride];
      for (int i = 0; i < inner; ++i) {
        const double horizontal = cos_lat * static_cast<double>(depth[i]);
        ox[i] = horizontal * sin_lon[i];
        oy[i] = sin_lat * static_cast<double>(depth[i]);
        oz[i] = -(horizontal * cos_lon[i]);
      }
      if (inner < cols) {  // Column `width`: column 0.
        const double horizontal = cos_lat * static_cast<double>(depth_row[0]);
        ox[inner] = horizontal * dirs_.sin_lon[0];
        oy[inner] = sin_lat * static_cast<double>(depth_row[0]);
        oz[inner] = -(horizontal * dirs_.cos_lon[0]);
      }
    }
  }

  // The level-1 blocks bx_begin, bx_begin + 1, ... of block row `by` in the
  // current tile, two blocks per vector (lane 0 block bx, lane 1 block bx + 1),
  // with exactly the arithmetic of BlockError. Returns the first block not
  // done (at most one is left for BlockError).
  int Level1Pairs(int by, int bx_begin, int bx_end, TileCache* c) {
    using internal::F64x2;
    using internal::LoadF64x2;
    using internal::UnpackHi;
    using internal::UnpackLo;
    const size_t stride = (size_t{1} << levels()) + 1;
    const size_t quads = static_cast<size_t>(nx_[0]);
    int bx = bx_begin;
    for (; bx + 2 <= bx_end; bx += 2) {
      const int x0 = 2 * bx, y0 = 2 * by;
      const uint8_t* f0 = &full_[static_cast<size_t>(y0) * quads + x0];
      const uint8_t* f1 = f0 + quads;
      const bool mergeable[2] = {(f0[0] & f0[1] & f1[0] & f1[1]) != 0,
                                 (f0[2] & f0[3] & f1[2] & f1[3]) != 0};
      if (!mergeable[0] && !mergeable[1]) continue;  // Both stay infinite.
      PrepareTile(c);
      // Node (x0 + i, y0 + r) of lane 0 and (x0 + 2 + i, y0 + r) of lane 1:
      // row r of a plane gives nodes i = 0, 1, 2 of both lanes.
      const size_t top = static_cast<size_t>(y0 - c->y0) * stride + (x0 - c->x0);
      auto load_row = [](const double* q, F64x2 out[3]) {
        const F64x2 a = LoadF64x2(q), b = LoadF64x2(q + 2), c = LoadF64x2(q + 4);
        out[0] = UnpackLo(a, b);
        out[1] = UnpackHi(a, b);
        out[2] = UnpackLo(b, c);
      };
      // Corners A (0, 0), B (2, 0), C (0, 2), D (2, 2).
      F64x2 n0, n1, n2, len;
      {
        const size_t bottom = top + 2 * stride;
        auto corners = [&](const std::vector<double>& plane, F64x2* u, F64x2* v) {
          F64x2 row0[3], row2[3];
          load_row(&plane[top], row0);
          load_row(&plane[bottom], row2);
          *u = row2[2] - row0[0];  // D - A
          *v = row2[0] - row0[2];  // C - B
        };
        F64x2 u0, u1, u2, v0, v1, v2;
        corners(c->px, &u0, &v0);
        corners(c->py, &u1, &v1);
        corners(c->pz, &u2, &v2);
        n0 = u1 * v2 - u2 * v1;
        n1 = u2 * v0 - u0 * v2;
        n2 = u0 * v1 - u1 * v0;
        len = internal::SqrtF64x2(n0 * n0 + n1 * n1 + n2 * n2);
        n0 = n0 / len;
        n1 = n1 / len;
        n2 = n2 / len;
      }
      F64x2 lo = internal::SplatF64x2(kInf), hi = internal::SplatF64x2(-kInf);
      for (int r = 0; r < 3; ++r) {
        const size_t at = top + r * stride;
        F64x2 X[3], Y[3], Z[3];
        load_row(&c->px[at], X);
        load_row(&c->py[at], Y);
        load_row(&c->pz[at], Z);
        for (int i = 0; i < 3; ++i) {
          const F64x2 t = n0 * X[i] + n1 * Y[i] + n2 * Z[i];
          lo = internal::MinF64x2(lo, t);
          hi = internal::MaxF64x2(hi, t);
        }
      }
      const double lens[2] = {internal::Lane0(len), internal::Lane1(len)};
      const double los[2] = {internal::Lane0(lo), internal::Lane1(lo)};
      const double his[2] = {internal::Lane0(hi), internal::Lane1(hi)};
      for (int lane = 0; lane < 2; ++lane) {
        if (!mergeable[lane] || !(lens[lane] > 0.0)) continue;
        error_[1][Index(1, bx + lane, by)] = SlabError(los[lane], his[lane], 0.0);
      }
    }
    return bx;
  }

  // Spec/mesh.md Sec. 5.2: the children must be mergeable; the plane normal is
  // the cross product of the block's diagonals; the slab is the range of n.p
  // over the block's (s+1)^2 nodes.
  double BlockError(int k, int bx, int by, TileCache* cache) {
    const int s = 1 << k;
    const int x0 = bx * s, y0 = by * s;
    double children = 0.0;
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 2; ++i) {
        if (k == 1) {
          if (!full_[static_cast<size_t>(y0 + j) * nx_[0] + x0 + i]) return kInf;
        } else {
          children = std::max(children, Error(k - 1, 2 * bx + i, 2 * by + j));
        }
      }
    }
    if (!(children <= max_error_)) return kInf;
    PrepareTile(cache);
    // Node (x0 + i, y0 + j) is cached at index top + j * stride + i.
    const size_t stride = (size_t{1} << levels()) + 1;
    const size_t top = static_cast<size_t>(y0 - cache->y0) * stride + (x0 - cache->x0);
    const size_t bottom = top + static_cast<size_t>(s) * stride;
    auto position = [&](size_t node, double out[3]) {
      out[0] = cache->px[node];
      out[1] = cache->py[node];
      out[2] = cache->pz[node];
    };
    double a[3], b[3], c[3], d[3];
    position(top, a);
    position(top + s, b);
    position(bottom, c);
    position(bottom + s, d);
    const double u[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    const double v[3] = {c[0] - b[0], c[1] - b[1], c[2] - b[2]};
    double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0.0)) return kInf;
    for (double& e : n) e /= len;
    // n . p of every node, two nodes per vector (the same products and sums
    // as n[0] * x + n[1] * y + n[2] * z per node), with running minima and
    // maxima; the range does not depend on the order of the nodes.
    using internal::F64x2;
    const F64x2 n0 = internal::SplatF64x2(n[0]), n1 = internal::SplatF64x2(n[1]),
                n2 = internal::SplatF64x2(n[2]);
    F64x2 lo2 = internal::SplatF64x2(kInf), hi2 = internal::SplatF64x2(-kInf);
    F64x2 lo2b = lo2, hi2b = hi2;
    double lo0 = kInf, hi0 = -kInf;
    for (size_t row = top; row <= bottom; row += stride) {
      const double* qx = &cache->px[row];
      const double* qy = &cache->py[row];
      const double* qz = &cache->pz[row];
      int x = 0;
      for (; x + 4 <= s; x += 4) {
        const F64x2 t = n0 * internal::LoadF64x2(qx + x) + n1 * internal::LoadF64x2(qy + x) +
                        n2 * internal::LoadF64x2(qz + x);
        const F64x2 tb = n0 * internal::LoadF64x2(qx + x + 2) +
                         n1 * internal::LoadF64x2(qy + x + 2) +
                         n2 * internal::LoadF64x2(qz + x + 2);
        lo2 = internal::MinF64x2(lo2, t);
        hi2 = internal::MaxF64x2(hi2, t);
        lo2b = internal::MinF64x2(lo2b, tb);
        hi2b = internal::MaxF64x2(hi2b, tb);
      }
      for (; x + 2 <= s; x += 2) {
        const F64x2 t = n0 * internal::LoadF64x2(qx + x) + n1 * internal::LoadF64x2(qy + x) +
                        n2 * internal::LoadF64x2(qz + x);
        lo2 = internal::MinF64x2(lo2, t);
        hi2 = internal::MaxF64x2(hi2, t);
      }
      const double t = n[0] * qx[s] + n[1] * qy[s] + n[2] * qz[s];  // x == s (s is even).
      lo0 = std::min(lo0, t);
      hi0 = std::max(hi0, t);
    }
    lo2 = internal::MinF64x2(lo2, lo2b);
    hi2 = internal::MaxF64x2(hi2, hi2b);
    const double lo1 = std::min(internal::Lane0(lo2), internal::Lane1(lo2));
    const double hi1 = std::max(internal::Lane0(hi2), internal::Lane1(hi2));
    return SlabError(std::min(lo0, lo1), std::max(hi0, hi1), children);
  }

  // The error of a block whose n.p range is [lo, hi] and whose children's
  // largest error is `children` (spec/mesh.md Sec. 5.2 steps 2-3), infinity
  // if it cannot be merged or exceeds max_error_.
  double SlabError(double lo, double hi, double children) const {
    const double delta = 0.5 * (hi - lo);
    const double offset = std::fabs(0.5 * (hi + lo));
    if (!(offset > delta)) return kInf;  // The slab contains the centre.
    const double error = std::max(children, 2.0 * delta / (offset - delta));
    return error <= max_error_ ? error : kInf;
  }

  const TwoLayerPanorama& p_;
  const Directions& dirs_;
  int layer_;
  double max_error_;
  std::vector<uint8_t> full_;
  std::vector<uint8_t> tile_has_full_;  // Per tile of the largest block size, row-major.
  std::vector<int> nx_, ny_;
  std::vector<std::vector<double>> error_;
  int tile_ = 1;  // Side of the largest block, in quads.
};

// The triangles of BuildMesh(). A quad whose four front nodes are linked
// around it has two (AddQuadTriangles' corner-B and corner-C triangles) if it
// has no back node, four if its back nodes are linked around it as well;
// other quads are counted rule by rule. `back` is null without the back layer.
int64_t CountFullTriangles(const TwoLayerPanorama& p, const LayerPyramid& front,
                           const LayerPyramid* back) {
  const bool use_back = back != nullptr;
  const int w = p.width(), qh = p.height() - 1;
  std::vector<uint8_t> back_in_column(w + 8, 0);  // See BackInColumns; zero without the back layer.
  int64_t triangles = 0;
  for (int y = 0; y < qh; ++y) {
    if (use_back) BackInColumns(p, y, back_in_column.data());
    const uint8_t* full = front.FullRow(y);
    const uint8_t* bic = back_in_column.data();
    for (int x = 0; x < w; ++x) {
      // Eight front-full quads without back nodes: two triangles each.
      if ((x & 7) == 0 && x + 8 <= w &&
          (Load64(full + x) & ~(Load64(bic + x) | Load64(bic + x + 1))) == kOnes) {
        triangles += 16;
        x += 7;
        continue;
      }
      if (full[x] && !(bic[x] | bic[x + 1])) {
        triangles += 2;
      } else if (full[x] && use_back && back->FullQuad(x, y)) {
        triangles += 4;
      } else {
        triangles += CountQuadTriangles(p, x, y, use_back, 0);
      }
    }
  }
  return triangles;
}

// Adds to the difference array `saving` (over threshold steps) the triangles
// each block of `py` saves at the steps where it is a leaf: a leaf of 2^k x
// 2^k quads replaces 2 * 4^k triangles by 2, and a block is a leaf for the
// steps i with error <= steps[i] < its parent's error. step_of(e) is the
// finest step i with e <= steps[i], or -1.
template <typename StepOf>
void AddSavings(const LayerPyramid& py, const StepOf& step_of, int threads,
                std::vector<int64_t>* saving) {
  // Each block's step, level by level from the top, so that a block finds its
  // parent's step in the level above. Rows of a level go to threads in
  // chunks, each with its own difference array (sums do not depend on the
  // order).
  std::vector<int8_t> parent_steps, block_steps;
  const int64_t chunks = 4 * static_cast<int64_t>(threads);
  std::vector<std::vector<int64_t>> partial(static_cast<size_t>(chunks),
                                            std::vector<int64_t>(saving->size(), 0));
  for (int k = py.levels(); k >= 1; --k) {
    const int64_t s = (int64_t{2} << (2 * k)) - 2;
    const int nx = py.nx(k);
    block_steps.assign(static_cast<size_t>(nx) * py.ny(k), -1);
    ParallelFor(0, chunks, threads, [&](int64_t c) {
      int64_t row_begin, row_end;
      ChunkRange(py.ny(k), chunks, c, &row_begin, &row_end);
      std::vector<int64_t>& out = partial[c];
      for (int by = static_cast<int>(row_begin); by < row_end; ++by) {
        const double* error = py.ErrorRow(k, by);
        int8_t* steps = block_steps.data() + static_cast<size_t>(by) * nx;
        // Blocks with a parent: columns below parent_nx in a row below the
        // parent level's last row.
        const bool parent_row = k < py.levels() && by / 2 < py.ny(k + 1);
        const int parent_nx = parent_row ? py.nx(k + 1) : 0;
        const int8_t* parents =
            parent_row ? parent_steps.data() + static_cast<size_t>(by / 2) * parent_nx : nullptr;
        for (int bx = 0; bx < nx; ++bx) {
          const int last = step_of(error[bx]);
          if (last < 0) continue;
          steps[bx] = static_cast<int8_t>(last);
          const int parent = bx / 2 < parent_nx ? parents[bx / 2] : -1;
          out[parent + 1] += s;  // i in (parent, last].
          out[last + 1] -= s;
        }
      }
    });
    parent_steps.swap(block_steps);
  }
  for (const std::vector<int64_t>& p : partial) {
    for (size_t i = 0; i < p.size(); ++i) (*saving)[i] += p[i];
  }
}

struct Leaf {
  int layer, level, x0, y0;
  double error;
};

// The corner a patch fans from (spec/mesh.md Sec. 5.4 step 3), given the
// number of kept nodes strictly inside each side of its ring (A-C, C-D, D-B,
// B-A): the first corner, in the order A, C, D, B, with no extra vertex on
// either of its sides, or -1 (a fan from the block's centre).
int PatchApex(const size_t extra[4]) {
  for (int c = 0; c < 4; ++c) {
    if (extra[c] == 0 && extra[(c + 3) & 3] == 0) return c;
  }
  return -1;
}

// The merged blocks at threshold tau, ordered by (layer, level from largest,
// block row, block column). Rows of a level go to threads in chunks whose
// leaves are joined in order.
std::vector<Leaf> SelectLeaves(const std::vector<LayerPyramid>& pyramids, double tau,
                               int threads) {
  std::vector<Leaf> leaves;
  if (tau < 0) return leaves;
  const int64_t chunks = 4 * static_cast<int64_t>(threads);
  // parts[(layer, level) group * chunks + chunk], joined in order at the end.
  std::vector<std::vector<Leaf>> parts;
  for (size_t l = 0; l < pyramids.size(); ++l) {
    const LayerPyramid& py = pyramids[l];
    for (int k = py.levels(); k >= 1; --k) {
      const size_t group = parts.size();
      parts.resize(group + static_cast<size_t>(chunks));
      ParallelFor(0, chunks, threads, [&](int64_t c) {
        int64_t row_begin, row_end;
        ChunkRange(py.ny(k), chunks, c, &row_begin, &row_end);
        std::vector<Leaf>& out = parts[group + static_cast<size_t>(c)];
        for (int by = static_cast<int>(row_begin); by < row_end; ++by) {
          const double* error = py.ErrorRow(k, by);
          const bool parent_row = k < py.levels() && by / 2 < py.ny(k + 1);
          const int parent_nx = parent_row ? py.nx(k + 1) : 0;
          const double* parents = parent_row ? py.ErrorRow(k + 1, by / 2) : nullptr;
          for (int bx = 0; bx < py.nx(k); ++bx) {
            const double e = error[bx];
            if (!(e <= tau)) continue;
            if (bx / 2 < parent_nx && parents[bx / 2] <= tau) continue;  // The parent is merged.
            out.push_back({static_cast<int>(l), k, bx << k, by << k, e});
          }
        }
      });
    }
  }
  size_t total = 0;
  for (const std::vector<Leaf>& part : parts) total += part.size();
  leaves.reserve(total);
  for (const std::vector<Leaf>& part : parts) leaves.insert(leaves.end(), part.begin(), part.end());
  return leaves;
}

// Per layer, whether a leaf of that layer covers the quad (1 or 0); the back
// layer's only with use_back.
void CoverLeafQuads(const TwoLayerPanorama& p, bool use_back, const std::vector<Leaf>& leaves, int threads,
                    std::vector<uint8_t> covered[kNumLayers]) {
  const int w = p.width(), qh = p.height() - 1;
  for (int l = 0; l < (use_back ? kNumLayers : 1); ++l) {
    covered[l].assign(static_cast<size_t>(w) * qh, 0);
  }
  const int64_t num_leaves = static_cast<int64_t>(leaves.size());
  ParallelFor(0, num_leaves, threads, [&](int64_t i) {  // Leaves never overlap.
    const Leaf& leaf = leaves[i];
    const int s = 1 << leaf.level;
    uint8_t* row = &covered[leaf.layer][static_cast<size_t>(leaf.y0) * w + leaf.x0];
    if (s == 2) {  // Most leaves: two 2-byte stores instead of two memset calls.
      const uint16_t ones = 0x0101;
      std::memcpy(row, &ones, 2);
      std::memcpy(row + w, &ones, 2);
      return;
    }
    for (int y = 0; y < s; ++y, row += w) std::memset(row, 1, static_cast<size_t>(s));
  }, 1024);
}

// Step 1: the pixel-quad triangles the leaves leave, rows y_begin..y_end.
// A quad covered by leaves of every layer that has a node at its corners
// has no triangle left (each triangle starts at a corner node of an
// uncovered layer).
void AddUncoveredQuads(const TwoLayerPanorama& p, bool use_back, const std::vector<uint8_t> covered[kNumLayers],
                       int64_t y_begin, int64_t y_end, MeshAssembler* out) {
  const int w = p.width();
  out->Reserve(static_cast<size_t>(w) * (y_end - y_begin) / 2 + 1024);
  // See BackInColumns; zero without the back layer.
  std::vector<uint8_t> back_in_column(w + 8, 0);
  const uint8_t* bic = back_in_column.data();
  for (int y = static_cast<int>(y_begin); y < y_end; ++y) {
    const uint8_t* front_covered = &covered[kFront][static_cast<size_t>(y) * w];
    const uint8_t* back_covered = use_back ? &covered[kBack][static_cast<size_t>(y) * w] : nullptr;
    if (use_back) BackInColumns(p, y, back_in_column.data());
    for (int x = 0; x < w; ++x) {
      // Eight quads covered in front without back nodes have no triangle.
      if ((x & 7) == 0 && x + 8 <= w &&
          (Load64(front_covered + x) & ~(Load64(bic + x) | Load64(bic + x + 1))) == kOnes) {
        x += 7;
        continue;
      }
      if (!front_covered[x]) {
        const unsigned skip = use_back ? static_cast<unsigned>(back_covered[x]) << 1 : 0u;
        AddQuadTriangles(p, x, y, use_back, skip, out);
        continue;
      }
      // Covered in front: triangles remain only from back nodes not covered.
      if (!(bic[x] | bic[x + 1]) || back_covered[x]) continue;
      AddQuadTriangles(p, x, y, use_back, 1u, out);
    }
  }
}

// The nodes kept by the simplified mesh (step 2), by node number
// pixel * 2 + layer; a column of w is column 0's.
class KeptNodes {
 public:
  explicit KeptNodes(const TwoLayerPanorama& p)
      : p_(p), w_(p.width()), kept_(static_cast<size_t>(p.width()) * p.height() * 2, 0) {}

  size_t node(int x, int y, int layer) const { return p_.index(x == w_ ? 0 : x, y) * 2 + layer; }
  bool is_kept(size_t node) const { return kept_[node] != 0; }
  bool is_kept(int x, int y, int layer) const { return is_kept(node(x, y, layer)); }
  void Keep(size_t node) { kept_[node] = 1; }
  void Release() { std::vector<uint8_t>().swap(kept_); }

 private:
  const TwoLayerPanorama& p_;
  int w_;
  std::vector<uint8_t> kept_;
};

// Step 2, kept nodes: every vertex of the remaining pixel-quad triangles
// and every leaf corner. A band's triangles use the nodes of its rows and
// of the row below, so bands of one parity never share a node: even bands,
// then odd ones. Leaf corners are few.
void KeepNodes(const std::vector<MeshAssembler>& quad_parts, const std::vector<Leaf>& leaves, int threads,
               KeptNodes* kept) {
  const int64_t row_bands = static_cast<int64_t>(quad_parts.size());
  for (int parity = 0; parity < 2; ++parity) {
    ParallelFor(0, (row_bands + 1 - parity) / 2, threads, [&](int64_t half) {
      for (NodeRef r : quad_parts[2 * half + parity].refs()) kept->Keep(r & ~kSeamBit);
    });
  }
  for (const Leaf& leaf : leaves) {
    const int s = 1 << leaf.level;
    kept->Keep(kept->node(leaf.x0, leaf.y0, leaf.layer));
    kept->Keep(kept->node(leaf.x0 + s, leaf.y0, leaf.layer));
    kept->Keep(kept->node(leaf.x0, leaf.y0 + s, leaf.layer));
    kept->Keep(kept->node(leaf.x0 + s, leaf.y0 + s, leaf.layer));
  }
}

// The triangles of a leaf's patch, from the kept nodes on the sides of its
// ring (AddPatch builds the same patch): two for a bare quad, n - 2 for a
// fan from a corner, n for a fan from the centre.
int64_t CountPatchTriangles(const Leaf& leaf, const KeptNodes& kept) {
  const int s = 1 << leaf.level, x0 = leaf.x0, y0 = leaf.y0, l = leaf.layer;
  size_t extra[4] = {0, 0, 0, 0};  // Sides A-C, C-D, D-B, B-A.
  for (int i = 1; i < s; ++i) {
    extra[0] += kept.is_kept(x0, y0 + i, l);
    extra[1] += kept.is_kept(x0 + i, y0 + s, l);
    extra[2] += kept.is_kept(x0 + s, y0 + i, l);
    extra[3] += kept.is_kept(x0 + i, y0, l);
  }
  const int64_t n = static_cast<int64_t>(4 + extra[0] + extra[1] + extra[2] + extra[3]);
  return n == 4 ? 2 : (PatchApex(extra) >= 0 ? n - 2 : n);
}

// Step 3: the patch of one leaf, its border's kept nodes (`ring`: scratch)
// fanned from a corner or the centre.
void AddPatch(const TwoLayerPanorama& p, const Leaf& leaf, const KeptNodes& kept, std::vector<NodeRef>* ring,
              MeshAssembler* out) {
  const int w = p.width();
  const int s = 1 << leaf.level, x0 = leaf.x0, y0 = leaf.y0, l = leaf.layer;
  auto ref = [&](int x, int y) {
    return x == w ? MakeNodeRef(p, 0, y, l, true) : MakeNodeRef(p, x, y, l, false);
  };
  // Border counter-clockwise seen from the centre: down the left side,
  // right along the bottom, up the right side, left along the top.
  // corner[] holds the ring positions of A, C, D, B; side i runs from
  // corner i to i + 1.
  ring->clear();
  size_t corner[4];
  corner[0] = ring->size();
  for (int y = y0; y < y0 + s; ++y) {
    if (y == y0 || kept.is_kept(x0, y, l)) ring->push_back(ref(x0, y));
  }
  corner[1] = ring->size();
  for (int x = x0; x < x0 + s; ++x) {
    if (x == x0 || kept.is_kept(x, y0 + s, l)) ring->push_back(ref(x, y0 + s));
  }
  corner[2] = ring->size();
  for (int y = y0 + s; y > y0; --y) {
    if (y == y0 + s || kept.is_kept(x0 + s, y, l)) ring->push_back(ref(x0 + s, y));
  }
  corner[3] = ring->size();
  for (int x = x0 + s; x > x0; --x) {
    if (x == x0 + s || kept.is_kept(x, y0, l)) ring->push_back(ref(x, y0));
  }
  const std::vector<NodeRef>& r = *ring;
  const size_t n = r.size();
  if (n == 4) {
    // Corners A, C, D, B: the two triangles of a pixel quad (A-D diagonal).
    out->AddTriangle(r[3], r[0], r[2]);
    out->AddTriangle(r[1], r[2], r[0]);
    return;
  }
  // A fan from a corner whose two sides have no extra vertex has no
  // degenerate triangle and needs n - 2 triangles; otherwise fan from the
  // block's centre node (n triangles).
  size_t extra[4];
  for (int i = 0; i < 4; ++i) extra[i] = (i == 3 ? n : corner[i + 1]) - corner[i] - 1;
  const int apex = PatchApex(extra);
  if (apex >= 0) {
    const size_t v = corner[apex];
    for (size_t i = 1; i + 1 < n; ++i) out->AddTriangle(r[v], r[(v + i) % n], r[(v + i + 1) % n]);
  } else {
    const NodeRef centre = ref(x0 + s / 2, y0 + s / 2);
    for (size_t i = 0; i < n; ++i) out->AddTriangle(centre, r[i], r[(i + 1) % n]);
  }
}

// Builds the simplified mesh for a set of leaves (spec/mesh.md Sec. 5.4) and
// sets *triangles to its triangle count. If `count_limit` >= 0 and the count
// exceeds it, returns an empty mesh (the caller only needs the count). Rows
// of quads and runs of leaves go to threads in bands whose triangles are
// joined in order, so the mesh does not depend on the number of threads.
Mesh Assemble(const TwoLayerPanorama& p, bool use_back, const std::vector<Leaf>& leaves,
              int threads, int64_t count_limit, int64_t* triangles) {
  const int qh = p.height() - 1;
  std::vector<uint8_t> covered[kNumLayers];
  CoverLeafQuads(p, use_back, leaves, threads, covered);

  // Step 1, remaining pixel-quad triangles, in bands of rows.
  const int64_t row_bands = std::min<int64_t>(qh, 8 * static_cast<int64_t>(threads));
  std::vector<MeshAssembler> quad_parts(static_cast<size_t>(std::max<int64_t>(row_bands, 0)),
                                        MeshAssembler(p));
  ParallelFor(0, row_bands, threads, [&](int64_t band) {
    int64_t y_begin, y_end;
    ChunkRange(qh, row_bands, band, &y_begin, &y_end);
    AddUncoveredQuads(p, use_back, covered, y_begin, y_end, &quad_parts[band]);
  });
  KeptNodes kept(p);
  KeepNodes(quad_parts, leaves, threads, &kept);
  const int64_t num_leaves = static_cast<int64_t>(leaves.size());
  const int64_t leaf_runs = std::min<int64_t>(num_leaves, 8 * static_cast<int64_t>(threads));
  // Triangles of each run of leaves, when counted first (then exact
  // reservations for step 3).
  std::vector<int64_t> run_triangles;
  if (count_limit >= 0) {
    run_triangles.assign(static_cast<size_t>(leaf_runs), 0);
    // Only the count may be needed: each patch's.
    int64_t quad_triangles = 0;
    for (const MeshAssembler& part : quad_parts) quad_triangles += part.num_triangles();
    ParallelFor(0, leaf_runs, threads, [&](int64_t run) {
      int64_t first, last;
      ChunkRange(num_leaves, leaf_runs, run, &first, &last);
      int64_t count = 0;
      for (int64_t li = first; li < last; ++li) count += CountPatchTriangles(leaves[li], kept);
      run_triangles[run] = count;
    });
    int64_t total = quad_triangles;
    for (int64_t c : run_triangles) total += c;
    if (total > count_limit) {
      *triangles = total;
      return Mesh();
    }
  }
  // Step 3, patches, in runs of leaves.
  std::vector<MeshAssembler> patch_parts(static_cast<size_t>(leaf_runs), MeshAssembler(p));
  ParallelFor(0, leaf_runs, threads, [&](int64_t run) {
    int64_t first, last;
    ChunkRange(num_leaves, leaf_runs, run, &first, &last);
    MeshAssembler& out = patch_parts[run];
    if (!run_triangles.empty()) {
      out.Reserve(static_cast<size_t>(run_triangles[run]));
    } else {
      size_t most = 0;  // A ring has at most 4 s nodes, a patch as many triangles.
      for (int64_t li = first; li < last; ++li) most += size_t{4} << leaves[li].level;
      out.Reserve(most);
    }
    std::vector<NodeRef> ring;
    for (int64_t li = first; li < last; ++li) AddPatch(p, leaves[li], kept, &ring, &out);
  });
  kept.Release();
  MeshAssembler out(p);
  size_t total = 0;
  for (const MeshAssembler& part : quad_parts) total += part.num_triangles();
  for (const MeshAssembler& part : patch_parts) total += part.num_triangles();
  *triangles = static_cast<int64_t>(total);
  if (count_limit >= 0 && *triangles > count_limit) return Mesh();
  out.Reserve(total);
  for (MeshAssembler& part : quad_parts) out.Append(&part);
  for (MeshAssembler& part : patch_parts) out.Append(&part);
  return out.Finish(threads);
}

}  // namespace

Status MeshSimplifyOptions::Check() const {
  if (max_triangles < 0 || max_triangles > (int64_t{1} << 31)) {
    return InvalidArgument("max_triangles " + std::to_string(max_triangles) +
                           " is outside [0, 2^31]");
  }
  if (!(max_relative_error > 0.0 && max_relative_error <= 0.5)) {
    return InvalidArgument("max_relative_error " + std::to_string(max_relative_error) +
                           " is outside (0, 0.5]");
  }
  if (max_block_size < 2 || max_block_size > 256 || (max_block_size & (max_block_size - 1))) {
    return InvalidArgument("max_block_size " + std::to_string(max_block_size) +
                           " is not a power of two in [2, 256]");
  }
  MeshBuildOptions build;
  build.max_pixels = max_pixels;
  build.num_threads = num_threads;
  return build.Check();
}

StatusOr<SimplifiedMesh> BuildSimplifiedMesh(const TwoLayerPanorama& pano,
                                             const MeshSimplifyOptions& options) {
  CASUAL3D_RETURN_IF_ERROR(options.Check());
  CASUAL3D_RETURN_IF_ERROR(CheckMeshInput(pano, options.max_pixels, options.validate_input));
  const int w = pano.width();
  const bool use_back = options.include_back_layer;

  int levels = 0;
  while ((2 << levels) <= options.max_block_size) ++levels;
  const Directions dirs(w, pano.height());
  const int threads = ResolveThreads(options.num_threads);
  std::vector<LayerPyramid> pyramids;
  pyramids.reserve(kNumLayers);
  for (int l = 0; l < (use_back ? kNumLayers : 1); ++l) {
    pyramids.emplace_back(pano, dirs, l, levels, options.max_relative_error, threads);
  }
  {
    // Block errors, by rows of tiles of both layers.
    std::vector<std::pair<int, int>> rows;  // (layer, tile row)
    for (size_t l = 0; l < pyramids.size(); ++l) {
      for (int ty = 0; ty < pyramids[l].num_tile_rows(); ++ty) {
        rows.emplace_back(static_cast<int>(l), ty);
      }
    }
    ParallelFor(0, static_cast<int64_t>(rows.size()), threads, [&](int64_t i) {
      // 400 KB for 128-quad tiles: each thread keeps its own between calls.
      static thread_local TileCache cache;
      pyramids[rows[i].first].EvaluateTileRow(rows[i].second, &cache);
    });
    for (LayerPyramid& py : pyramids) py.ReleaseScratch();
  }

  SimplifiedMesh result;
  result.full_triangles =
      CountFullTriangles(pano, pyramids[kFront], use_back ? &pyramids[kBack] : nullptr);

  // Candidate thresholds, coarsest first, and the triangle count each would
  // give before border vertices are added to the patches: a leaf of 2^k x 2^k
  // quads replaces 2 * 4^k triangles by 2. A block is a leaf for thresholds in
  // [its error, its parent's error).
  // steps[] is padded with -infinity up to kStepsPadded entries so that the
  // search below needs no bounds check.
  constexpr int kStepsPadded = 128;
  static_assert(kNumSteps < kStepsPadded, "the padded step table must hold every step");
  double steps[kStepsPadded];
  steps[0] = options.max_relative_error;
  for (int i = 1; i < kNumSteps; ++i) steps[i] = steps[i - 1] * kQuarterOctave;
  steps[kNumSteps] = 0.0;
  for (int i = kNumSteps + 1; i < kStepsPadded; ++i) steps[i] = -kInf;
  auto search_step = [&](double e) {  // The last (finest) step i with e <= steps[i], or -1.
    if (!(e <= steps[0])) return -1;
    // e <= steps[i] holds for a prefix of i (steps decrease): find its end
    // without data-dependent branches.
    int last = 0;
    for (int half = kStepsPadded / 2; half >= 1; half /= 2) {
      last = e <= steps[last + half] ? last + half : last;
    }
    return last;
  };
  // The same function through a table over the leading bits of e (exponent
  // and 4 mantissa bits): a bucket spans a factor of at most 2^(1/16), less
  // than the 2^(1/4) between steps, so the step of a bucket's smallest value
  // is the answer or one more than it for every e in the bucket.
  auto bucket_of = [](double e) {
    uint64_t bits;
    std::memcpy(&bits, &e, sizeof(bits));
    return bits >> 48;
  };
  const uint64_t first_bucket = bucket_of(steps[kNumSteps - 1]);
  std::vector<int8_t> bucket_step(bucket_of(steps[0]) - first_bucket + 1);
  for (size_t b = 0; b < bucket_step.size(); ++b) {
    const uint64_t low_bits = (first_bucket + b) << 48;
    double low;
    std::memcpy(&low, &low_bits, sizeof(low));
    bucket_step[b] = static_cast<int8_t>(search_step(low));
  }
  auto step_of = [&](double e) {
    if (!(e <= steps[0])) return -1;
    if (e <= steps[kNumSteps - 1]) return e <= 0.0 ? kNumSteps : kNumSteps - 1;
    const int g = bucket_step[bucket_of(e) - first_bucket];
    return e <= steps[g] ? g : g - 1;
  };
  std::vector<int64_t> saving(kNumSteps + 2, 0);  // Difference array over step indices.
  for (const LayerPyramid& py : pyramids) AddSavings(py, step_of, threads, &saving);
  std::vector<int64_t> estimate(kNumSteps + 1);
  int64_t running = 0;
  for (int i = 0; i <= kNumSteps; ++i) {
    running += saving[i];
    estimate[i] = result.full_triangles - running;
  }

  // The finest threshold whose estimate fits the budget. Patches take extra
  // border vertices (more triangles than estimated), so while the result is
  // over budget, retry with the estimate lowered by the measured excess.
  int64_t target = options.max_triangles;
  for (int attempt = 0; attempt < 8; ++attempt) {
    int step = 0;  // Coarsest: max_relative_error.
    double tau = steps[0];
    if (options.max_triangles > 0 && result.full_triangles <= target) {
      tau = -1.0;  // No merging needed.
    } else if (options.max_triangles > 0) {
      while (step < kNumSteps && estimate[step + 1] <= target) ++step;
      tau = steps[step];
    }
    const std::vector<Leaf> leaves = SelectLeaves(pyramids, tau, threads);
    // An attempt that another one will follow if it is over budget only
    // needs its triangle count.
    const bool may_retry = options.max_triangles > 0 && step != 0 && attempt + 1 < 8;
    int64_t triangles = 0;
    result.mesh = Assemble(pano, use_back, leaves, threads,
                           may_retry ? options.max_triangles : -1, &triangles);
    result.merged_blocks = static_cast<int64_t>(leaves.size());
    result.error_bound = 0.0;
    for (const Leaf& leaf : leaves) result.error_bound = std::max(result.error_bound, leaf.error);
    result.budget_met = options.max_triangles == 0 || triangles <= options.max_triangles;
    if (result.budget_met || step == 0) break;
    const int64_t excess = triangles - estimate[step];
    target = std::min(target - 1, options.max_triangles - excess);
  }
  return result;
}

}  // namespace casual3d
