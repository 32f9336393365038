#include "format/mesh_builder.h"

#include <cmath>
#include <string>
#include <utility>

#include "format/parallel.h"

namespace casual3d {
namespace {

// pi/2 split so that q * kPiOver2Hi is exact for |q| < 2^20 (fdlibm's pio2_1).
constexpr double kPiOver2Hi = 1.57079632673412561417e+00;
constexpr double kPiOver2Lo = 6.07710050650619224932e-11;
constexpr double kTwoOverPi = 6.36619772367581382433e-01;

}  // namespace

Status MeshBuildOptions::Check() const {
  if (max_pixels < 1 || max_pixels > kMeshPixelLimit) {
    return InvalidArgument("max_pixels " + std::to_string(max_pixels) + " is outside [1, " +
                           std::to_string(kMeshPixelLimit) + "]");
  }
  if (num_threads < 0 || num_threads > 256) {
    return InvalidArgument("num_threads " + std::to_string(num_threads) + " is outside [0, 256]");
  }
  return Status::Ok();
}

void DeterministicSinCos(double angle_rad, double* sin_out, double* cos_out) {
  // Cody-Waite reduction to r in [-pi/4, pi/4], then Taylor polynomials whose
  // first omitted terms are below 1e-19 on that interval.
  const double q = std::floor(angle_rad * kTwoOverPi + 0.5);
  const double r = (angle_rad - q * kPiOver2Hi) - q * kPiOver2Lo;
  const double r2 = r * r;
  const double s =
      r +
      r * r2 *
          (-1.0 / 6 +
           r2 * (1.0 / 120 +
                 r2 * (-1.0 / 5040 +
                       r2 * (1.0 / 362880 + r2 * (-1.0 / 39916800 +
                                                  r2 * (1.0 / 6227020800.0 +
                                                        r2 * (-1.0 / 1307674368000.0 +
                                                              r2 * (1.0 / 355687428096000.0))))))));
  const double c =
      1.0 +
      r2 * (-0.5 +
            r2 * (1.0 / 24 +
                  r2 * (-1.0 / 720 +
                        r2 * (1.0 / 40320 + r2 * (-1.0 / 3628800 +
                                                  r2 * (1.0 / 479001600.0 +
                                                        r2 * (-1.0 / 87178291200.0 +
                                                              r2 * (1.0 / 20922789888000.0))))))));
  const int quadrant = static_cast<int>(q - 4.0 * std::floor(q * 0.25));  // q mod 4 in [0, 3].
  switch (quadrant) {
    case 0:
      *sin_out = s;
      *cos_out = c;
      break;
    case 1:
      *sin_out = c;
      *cos_out = -s;
      break;
    case 2:
      *sin_out = -s;
      *cos_out = -c;
      break;
    default:
      *sin_out = -c;
      *cos_out = s;
      break;
  }
}

namespace {

// Counts instead of collecting triangles.
struct TriangleCounter {
  int count = 0;
  void AddTriangle(NodeRef, NodeRef, NodeRef) { ++count; }
};

// Spec/mesh.md Sec. 4: the corner triangles of one pixel quad.
template <typename Sink>
void QuadTriangles(const TwoLayerPanorama& p, int x, int y, bool use_back, unsigned skip_layers,
                   Sink* out) {
  // Corners A (top-left), B (top-right), C (bottom-left), D (bottom-right).
  enum { A = 0, B = 1, C = 2, D = 3 };
  const bool wrap = x + 1 == p.width();  // B and D are column 0, seen as column width.
  const int xb = wrap ? 0 : x + 1;
  const size_t idx[4] = {p.index(x, y), p.index(xb, y), p.index(x, y + 1), p.index(xb, y + 1)};
  auto ref = [&](int c, int l) {
    return static_cast<NodeRef>(idx[c] * 2 + l) | (wrap && (c == B || c == D) ? kSeamBit : 0u);
  };
  // The common cases first: four front nodes linked to each other around the
  // quad, and at its corners either no back node or four back nodes linked
  // to each other around it. The rules below then give exactly the corner-B
  // and corner-C triangles of each such layer, corner B's first, front before
  // back (corners A and D are closed by them).
  {
    const LayerData& f = p.layer(kFront);
    const LayerData& b = p.layer(kBack);
    // Links around the quad, two bits per direction: right and down at A,
    // down and left at B, right and up at C, left and up at D, all to `link`.
    auto linked_around = [&](const LayerData& d, unsigned link) {
      return d.present[idx[A]] == 1 && d.present[idx[B]] == 1 && d.present[idx[C]] == 1 &&
             d.present[idx[D]] == 1 && (d.links[idx[A]] & 0x0Fu) == link * 0x05u &&
             (d.links[idx[B]] & 0x3Cu) == link * 0x14u &&
             (d.links[idx[C]] & 0xC3u) == link * 0x41u && (d.links[idx[D]] & 0xF0u) == link * 0x50u;
    };
    if (linked_around(f, 1)) {
      const bool no_back = !use_back || !(b.present[idx[A]] | b.present[idx[B]] |
                                          b.present[idx[C]] | b.present[idx[D]]);
      if (no_back || linked_around(b, 2)) {
        const int layers = no_back ? 1 : 2;
        for (int l = 0; l < layers; ++l) {
          if (!(skip_layers & (1u << l))) out->AddTriangle(ref(B, l), ref(A, l), ref(D, l));
        }
        for (int l = 0; l < layers; ++l) {
          if (!(skip_layers & (1u << l))) out->AddTriangle(ref(C, l), ref(D, l), ref(A, l));
        }
        return;
      }
    }
  }
  // Local copies: bit l of present[c] is set if corner c has a usable node of
  // layer l; links[c][l] are its links (0 otherwise).
  unsigned present[4] = {0, 0, 0, 0};
  uint8_t links[4][kNumLayers] = {};
  for (int l = 0; l < (use_back ? kNumLayers : 1); ++l) {
    const LayerData& d = p.layer(l);
    for (int c = 0; c < 4; ++c) {
      if (d.present[idx[c]]) {
        present[c] |= 1u << l;
        links[c][l] = d.links[idx[c]];
      }
    }
  }
  if (!(present[A] | present[B] | present[C] | present[D])) return;
  // The layer of the node that (corner c, layer l) links to at corner oc in
  // direction dir, or -1. Never trusts a link blindly: the target must be a
  // usable node, so invalid panoramas stay safe.
  auto target = [&](int c, int l, Direction dir, int oc) -> int {
    const unsigned link = (links[c][l] >> (2 * dir)) & 3u;
    if (link == 0 || link == 3) return -1;
    const int t = static_cast<int>(link) - 1;
    return (present[oc] >> t) & 1u ? t : -1;
  };
  auto usable = [&](int c, int l) { return ((present[c] & ~skip_layers) >> l) & 1u; };
  // Corner A: links right and down; only where neither B nor C closes the
  // quad, otherwise the corner-B/C triangles cover this area.
  for (int l = 0; l < kNumLayers; ++l) {
    if (!usable(A, l)) continue;
    const int lb = target(A, l, kRight, B), lc = target(A, l, kDown, C);
    if (lb < 0 || lc < 0 || target(B, lb, kDown, D) >= 0 || target(C, lc, kRight, D) >= 0) continue;
    out->AddTriangle(ref(A, l), ref(C, lc), ref(B, lb));
  }
  // Corner B: links left and down; the quad splits along the A-D diagonal.
  for (int l = 0; l < kNumLayers; ++l) {
    if (!usable(B, l)) continue;
    const int la = target(B, l, kLeft, A), ld = target(B, l, kDown, D);
    if (la < 0 || ld < 0) continue;
    out->AddTriangle(ref(B, l), ref(A, la), ref(D, ld));
  }
  // Corner C: links up and right.
  for (int l = 0; l < kNumLayers; ++l) {
    if (!usable(C, l)) continue;
    const int la = target(C, l, kUp, A), ld = target(C, l, kRight, D);
    if (la < 0 || ld < 0) continue;
    out->AddTriangle(ref(C, l), ref(D, ld), ref(A, la));
  }
  // Corner D: links up and left; only where neither B nor C closes the quad.
  for (int l = 0; l < kNumLayers; ++l) {
    if (!usable(D, l)) continue;
    const int lb = target(D, l, kUp, B), lc = target(D, l, kLeft, C);
    if (lb < 0 || lc < 0 || target(B, lb, kLeft, A) >= 0 || target(C, lc, kUp, A) >= 0) continue;
    out->AddTriangle(ref(D, l), ref(B, lb), ref(C, lc));
  }
}

// Records which corner's triangles a quad emits (the first vertex of each
// corner triangle is its corner node).
struct CornerRecorder {
  size_t corner_pixel[4];
  unsigned corners = 0;
  void AddTriangle(NodeRef a, NodeRef, NodeRef) {
    const size_t pixel = (a & ~kSeamBit) >> 1;
    for (int c = 0; c < 4; ++c)
      if (corner_pixel[c] == pixel) corners |= 1u << c;
  }
};

}  // namespace

unsigned QuadCoverage(const TwoLayerPanorama& pano, int x, int y, bool use_back,
                      unsigned skip_layers) {
  const int xb = x + 1 == pano.width() ? 0 : x + 1;
  CornerRecorder r{{pano.index(x, y), pano.index(xb, y), pano.index(x, y + 1), pano.index(xb, y + 1)}};
  QuadTriangles(pano, x, y, use_back, skip_layers, &r);
  // Corner A's triangle covers the top and left quarters, B's top and right,
  // C's left and bottom, D's right and bottom.
  const bool a = r.corners & 1u, b = r.corners & 2u, c = r.corners & 4u, d = r.corners & 8u;
  return ((a || b) ? kQuarterTop : 0u) | ((a || c) ? kQuarterLeft : 0u) |
         ((b || d) ? kQuarterRight : 0u) | ((c || d) ? kQuarterBottom : 0u);
}

void AddQuadTriangles(const TwoLayerPanorama& pano, int x, int y, bool use_back,
                      unsigned skip_layers, MeshAssembler* out) {
  QuadTriangles(pano, x, y, use_back, skip_layers, out);
}

int CountQuadTriangles(const TwoLayerPanorama& pano, int x, int y, bool use_back,
                       unsigned skip_layers) {
  TriangleCounter counter;
  QuadTriangles(pano, x, y, use_back, skip_layers, &counter);
  return counter.count;
}

void MeshAssembler::ChooseAtlasHalves(int num_threads) {
  const NodeArray<uint8_t>& front_present = pano_.layer(kFront).present;
  const NodeArray<uint8_t>& back_present = pano_.layer(kBack).present;
  const int64_t triangles = static_cast<int64_t>(refs_.size() / 3);
  ParallelFor(0, triangles, num_threads, [&](int64_t t) {
    NodeRef* tri = &refs_[3 * t];
    const unsigned layers = (tri[0] & 1u) + (tri[1] & 1u) + (tri[2] & 1u);
    if (layers == 0 || layers == 3) return;  // One layer: its own half.
    // Vertices whose colour the other half would not show at their pixel:
    // a front node where a back node exists (sampled in the back half), a
    // back node where a front node exists (sampled in the front half).
    int wrong_in_back = 0, wrong_in_front = 0;
    for (int k = 0; k < 3; ++k) {
      const size_t pixel = (tri[k] & kNodeMask) >> 1;
      if (tri[k] & 1u) {
        wrong_in_front += front_present[pixel] ? 1 : 0;
      } else {
        wrong_in_back += back_present[pixel] ? 1 : 0;
      }
    }
    const NodeRef half = wrong_in_back <= wrong_in_front ? 1u : 0u;
    for (int k = 0; k < 3; ++k) {
      if ((tri[k] & 1u) != half) tri[k] |= kOtherHalfBit;
    }
  }, 65536);
}

namespace {

// Set bits of v: one instruction in wasm and where the target has POPCNT,
// else the parallel bit count (the compiler's fallback is a library call).
inline uint32_t PopCount(uint64_t v) {
#if defined(__wasm__) || defined(__POPCNT__)
  return static_cast<uint32_t>(__builtin_popcountll(v));
#else
  v = v - ((v >> 1) & 0x5555555555555555ull);
  v = (v & 0x3333333333333333ull) + ((v >> 2) & 0x3333333333333333ull);
  v = (v + (v >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return static_cast<uint32_t>((v * 0x0101010101010101ull) >> 56);
#endif
}

// A vertex key: node * 2 + (1 if its uv is in the other layer's half).
inline uint32_t KeyOf(NodeRef r) { return ((r & kNodeMask) << 1) | ((r & kOtherHalfBit) ? 1u : 0u); }

// A seam copy's slot: (row, layer, other half).
inline size_t SeamSlot(NodeRef r, int w) {
  const uint32_t node = r & kNodeMask;
  return 4 * static_cast<size_t>((node >> 1) / w) + 2 * (node & 1) + ((r & kOtherHalfBit) ? 1 : 0);
}

// The vertices the references use. Used keys are a bitmap with a running
// count per 64-bit word: the vertex index of a key is its rank among used
// keys (6 MB for 4096 x 2048 instead of a 128 MB index table). Seam copies
// are numbered after them.
struct VertexKeys {
  size_t words = 0;
  std::vector<uint64_t> used;
  std::vector<uint32_t> used_before;     // Used keys in the words before.
  std::vector<uint32_t> seam_vertex_of;  // By SeamSlot: index + 1; 0: unused.
  uint32_t regular = 0;                  // Vertices that are not seam copies.
  uint32_t count = 0;                    // All vertices.

  uint32_t VertexOf(uint32_t key) const {
    const uint64_t below = used[key >> 6] & ((uint64_t{1} << (key & 63)) - 1);
    return used_before[key >> 6] + PopCount(below);
  }
};

VertexKeys MarkVertexKeys(const std::vector<NodeRef>& refs, int w, int h, int threads) {
  VertexKeys k;
  const size_t keys = static_cast<size_t>(w) * h * 2 * 2;
  k.words = (keys + 63) / 64;
  k.used.assign(k.words, 0);
  k.seam_vertex_of.assign(4 * static_cast<size_t>(h), 0);
  // Each chunk of references marks its own bitmap (the first chunk `used`
  // itself); the bitmaps are then OR-ed word range by word range.
  const int64_t num_refs = static_cast<int64_t>(refs.size());
  const int mark_chunks = num_refs >= (int64_t{1} << 20) ? threads : 1;
  std::vector<std::vector<uint64_t>> more_used(static_cast<size_t>(mark_chunks - 1));
  std::vector<std::vector<uint32_t>> more_seams(static_cast<size_t>(mark_chunks - 1));
  ParallelFor(0, mark_chunks, threads, [&](int64_t c) {
    uint64_t* bits = k.used.data();
    uint32_t* seams = k.seam_vertex_of.data();
    if (c > 0) {
      more_used[c - 1].assign(k.words, 0);
      more_seams[c - 1].assign(k.seam_vertex_of.size(), 0);
      bits = more_used[c - 1].data();
      seams = more_seams[c - 1].data();
    }
    int64_t first, last;
    ChunkRange(num_refs, mark_chunks, c, &first, &last);
    for (int64_t i = first; i < last; ++i) {
      const NodeRef r = refs[i];
      if (r & kSeamBit) {
        seams[SeamSlot(r, w)] = 1;
      } else {
        const uint32_t key = KeyOf(r);
        bits[key >> 6] |= uint64_t{1} << (key & 63);
      }
    }
  });
  if (mark_chunks > 1) {
    ParallelFor(0, static_cast<int64_t>(k.words), threads, [&](int64_t i) {
      for (const auto& more : more_used) k.used[i] |= more[i];
    }, 1 << 14);
    for (const auto& more : more_seams) {
      for (size_t i = 0; i < k.seam_vertex_of.size(); ++i) k.seam_vertex_of[i] |= more[i];
    }
    std::vector<std::vector<uint64_t>>().swap(more_used);
  }
  k.used_before.resize(k.words);
  uint32_t count = 0;
  for (size_t i = 0; i < k.words; ++i) {
    k.used_before[i] = count;
    count += PopCount(k.used[i]);
  }
  k.regular = count;
  for (uint32_t& v : k.seam_vertex_of) {
    if (v) v = ++count;
  }
  k.count = count;
  return k;
}

// Writes vertices of `pano` into a mesh sized for them: position from the
// node's depth and its pixel's direction, normal, colour and uv.
class VertexWriter {
 public:
  VertexWriter(const TwoLayerPanorama& pano, Mesh* mesh) : pano_(pano), mesh_(*mesh) {
    const int w = pano.width(), h = pano.height();
    // Direction tables (Sec. 3 of spec/mesh.md): longitude per column and
    // latitude per row at pixel centres, with the deterministic sine/cosine.
    sin_lon_.resize(w);
    cos_lon_.resize(w);
    sin_lat_.resize(h);
    cos_lat_.resize(h);
    for (int x = 0; x < w; ++x) {
      DeterministicSinCos(((x + 0.5) / w - 0.5) * 2.0 * kPi, &sin_lon_[x], &cos_lon_[x]);
    }
    for (int y = 0; y < h; ++y) {
      DeterministicSinCos((0.5 - (y + 0.5) / h) * kPi, &sin_lat_[y], &cos_lat_[y]);
    }
    // Texture coordinates per column and per (row, layer), spec/mesh.md Sec. 3.
    u_of_.resize(w + 1);
    v_of_.resize(2 * static_cast<size_t>(h));
    for (int x = 0; x <= w; ++x) u_of_[x] = static_cast<float>((x + 0.5) / w);
    for (int y = 0; y < h; ++y) {
      for (int l = 0; l < kNumLayers; ++l) {
        v_of_[2 * y + l] = static_cast<float>((y + 0.5 + l * static_cast<double>(h)) / (2.0 * h));
      }
    }
  }

  // Writes vertex `index`: node (x, y, layer), its uv in atlas half `half`
  // (column w's for a seam copy).
  void Emit(uint32_t index, int x, int y, int layer, int half, bool seam) const {
    const LayerData& d = pano_.layer(layer);
    const size_t i = pano_.index(x, y);
    const double depth = d.depth_m[i];
    const double horizontal = cos_lat_[y] * depth;
    float* position = &mesh_.positions[3 * static_cast<size_t>(index)];
    float* normal = &mesh_.normals[3 * static_cast<size_t>(index)];
    uint8_t* color = &mesh_.colors[3 * static_cast<size_t>(index)];
    float* uv = &mesh_.uvs[2 * static_cast<size_t>(index)];
    position[0] = static_cast<float>(horizontal * sin_lon_[x]);
    position[1] = static_cast<float>(sin_lat_[y] * depth);
    position[2] = static_cast<float>(-(horizontal * cos_lon_[x]));
    for (int c = 0; c < 3; ++c) {
      normal[c] = d.normal[3 * i + c];
      color[c] = d.rgb[3 * i + c];
    }
    uv[0] = u_of_[seam ? pano_.width() : x];
    uv[1] = v_of_[2 * y + half];
  }

 private:
  const TwoLayerPanorama& pano_;
  Mesh& mesh_;
  std::vector<double> sin_lon_, cos_lon_, sin_lat_, cos_lat_;
  std::vector<float> u_of_, v_of_;
};

// Writes the vertices of the used keys in increasing order, i.e. (row,
// column, layer, half) order, in ranges of words whose first vertex index is
// known from used_before. A word holds the keys of 16 pixels; its first
// pixel's row and column are carried from word to word instead of divided
// out per key.
void EmitRegularVertices(const VertexKeys& k, int w, int threads, const VertexWriter& writer) {
  const int64_t word_chunks = k.regular >= (1u << 16) ? 8 * static_cast<int64_t>(threads) : 1;
  ParallelFor(0, word_chunks, threads, [&](int64_t c) {
    int64_t first, last;
    ChunkRange(static_cast<int64_t>(k.words), word_chunks, c, &first, &last);
    if (first >= last) return;
    const uint64_t first_pixel = static_cast<uint64_t>(first) * 16;
    int word_x = static_cast<int>(first_pixel % static_cast<uint64_t>(w));
    int word_y = static_cast<int>(first_pixel / static_cast<uint64_t>(w));
    uint32_t index = k.used_before[first];
    for (int64_t word = first; word < last; ++word) {
      for (uint64_t bits = k.used[word]; bits != 0; bits &= bits - 1) {
        const int bit = __builtin_ctzll(bits);
        int x = word_x + (bit >> 2), y = word_y;
        if (x >= w) {  // 16 pixels may run into the next rows when w < 16.
          y += x / w;
          x %= w;
        }
        const int l = (bit >> 1) & 1;
        const int other = bit & 1;
        writer.Emit(index++, x, y, l, l ^ other, false);
      }
      word_x += 16;
      if (word_x >= w) {
        word_y += word_x / w;
        word_x %= w;
      }
    }
  });
}

}  // namespace

Mesh MeshAssembler::Finish(int num_threads) {
  const int threads = ResolveThreads(num_threads);
  ChooseAtlasHalves(threads);
  const int w = pano_.width(), h = pano_.height();
  const VertexKeys keys = MarkVertexKeys(refs_, w, h, threads);

  Mesh mesh;
  mesh.positions.resize(3 * static_cast<size_t>(keys.count));
  mesh.normals.resize(3 * static_cast<size_t>(keys.count));
  mesh.uvs.resize(2 * static_cast<size_t>(keys.count));
  mesh.colors.resize(3 * static_cast<size_t>(keys.count));
  const VertexWriter writer(pano_, &mesh);
  EmitRegularVertices(keys, w, threads, writer);
  uint32_t index = keys.regular;
  for (int y = 0; y < h; ++y) {
    for (int l = 0; l < kNumLayers; ++l) {
      for (int other = 0; other < 2; ++other) {
        if (keys.seam_vertex_of[4 * y + 2 * l + other]) writer.Emit(index++, 0, y, l, l ^ other, true);
      }
    }
  }
  // References become indices in place (both are 32-bit).
  const int64_t num_refs = static_cast<int64_t>(refs_.size());
  ParallelFor(0, num_refs, threads, [&](int64_t i) {
    NodeRef& r = refs_[i];
    r = (r & kSeamBit) ? keys.seam_vertex_of[SeamSlot(r, w)] - 1 : keys.VertexOf(KeyOf(r));
  }, 1 << 16);
  mesh.indices = std::move(refs_);
  refs_ = std::vector<NodeRef>();
  return mesh;
}

Status CheckMeshInput(const TwoLayerPanorama& pano, int64_t max_pixels, bool validate) {
  const int64_t pixels = static_cast<int64_t>(pano.width()) * pano.height();
  if (pixels > max_pixels) {
    return LimitExceeded("panorama " + std::to_string(pano.width()) + "x" +
                         std::to_string(pano.height()) + " has " + std::to_string(pixels) +
                         " pixels, more than the mesh builder's limit of " +
                         std::to_string(max_pixels));
  }
  if (validate) {
    CASUAL3D_RETURN_IF_ERROR(pano.Validate());
  } else if (pano.width() < 1 || pano.height() < 1) {
    return InvalidData("panorama is empty");
  }
  if (pano.width() < 2) {
    return InvalidArgument("panorama width " + std::to_string(pano.width()) +
                           " is too small for a mesh: at least 2 columns are needed");
  }
  if (!validate) {
    // Without validation, at least make every array access in bounds.
    const size_t n = static_cast<size_t>(pixels);
    for (int l = 0; l < kNumLayers; ++l) {
      const LayerData& d = pano.layer(l);
      if (d.present.size() != n || d.rgb.size() != 3 * n || d.depth_m.size() != n ||
          d.normal.size() != 3 * n || d.label.size() != n || d.links.size() != n) {
        return InvalidData("panorama arrays do not match its size " + std::to_string(pano.width()) +
                           "x" + std::to_string(pano.height()));
      }
    }
  }
  return Status::Ok();
}

StatusOr<Mesh> BuildMesh(const TwoLayerPanorama& pano, const MeshBuildOptions& options) {
  CASUAL3D_RETURN_IF_ERROR(options.Check());
  CASUAL3D_RETURN_IF_ERROR(CheckMeshInput(pano, options.max_pixels, options.validate_input));
  MeshAssembler assembler(pano);
  // Counting first costs less than growing a vector of hundreds of megabytes.
  size_t triangles = 0;
  for (int y = 0; y + 1 < pano.height(); ++y) {
    for (int x = 0; x < pano.width(); ++x) {
      triangles += CountQuadTriangles(pano, x, y, options.include_back_layer, 0u);
    }
  }
  assembler.Reserve(triangles);
  for (int y = 0; y + 1 < pano.height(); ++y) {
    for (int x = 0; x < pano.width(); ++x) {
      AddQuadTriangles(pano, x, y, options.include_back_layer, 0u, &assembler);
    }
  }
  return assembler.Finish(options.num_threads);
}

}  // namespace casual3d
