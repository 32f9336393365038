#include "format/tile_codec.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <utility>

#if defined(__wasm_simd128__)
#include <wasm_simd128.h>
#endif

#include "format/parallel.h"

namespace casual3d {
namespace {

constexpr int kFlagFrontPresent = 1, kFlagBackPresent = 2, kFlagFrontLabel = 4,
              kFlagBackLabel = 8;
constexpr int kFlagReserved = 0xF0;
// The right and down links of a packed links byte (directions 0 and 1).
constexpr uint8_t kRightDownLinkBits = 0x0F;

std::string PixelName(int x, int y) {
  return "(" + std::to_string(x) + ", " + std::to_string(y) + ")";
}

// Colour of one layer half, with absent pixels filled from the nearest node of
// the row (or the nearest filled row) so that lossy coding spends few bits on them.
void EncodeColorHalf(const TwoLayerPanorama& pano, int layer, int x0, int y0, int w, int h,
                     uint8_t* out /* w*h*3, row-major */) {
  const LayerData& L = pano.layer(layer);
  std::vector<uint8_t> row_filled(h, 0);
  for (int y = 0; y < h; ++y) {
    uint8_t* row = out + static_cast<size_t>(y) * w * 3;
    int first = -1;
    for (int x = 0; x < w; ++x) {
      const size_t i = pano.index(x0 + x, y0 + y);
      if (L.present[i]) {
        for (int c = 0; c < 3; ++c) row[3 * x + c] = L.rgb[3 * i + c];
        if (first < 0) first = x;
      } else if (first >= 0) {
        for (int c = 0; c < 3; ++c) row[3 * x + c] = row[3 * (x - 1) + c];
      }
    }
    if (first < 0) continue;
    row_filled[y] = 1;
    for (int x = 0; x < first; ++x)
      for (int c = 0; c < 3; ++c) row[3 * x + c] = row[3 * first + c];
  }
  // Empty rows copy the nearest filled row above, then below.
  int last = -1;
  for (int y = 0; y < h; ++y) {
    if (row_filled[y]) {
      last = y;
    } else if (last >= 0) {
      std::copy_n(out + static_cast<size_t>(last) * w * 3, w * 3, out + static_cast<size_t>(y) * w * 3);
    }
  }
  int first_filled = -1;
  for (int y = 0; y < h && first_filled < 0; ++y)
    if (row_filled[y]) first_filled = y;
  if (first_filled < 0) {
    std::fill_n(out, static_cast<size_t>(w) * h * 3, uint8_t{128});
    return;
  }
  for (int y = 0; y < first_filled; ++y)
    std::copy_n(out + static_cast<size_t>(first_filled) * w * 3, w * 3,
                out + static_cast<size_t>(y) * w * 3);
}

}  // namespace

const char* TileImageKindName(TileImageKind kind) {
  switch (kind) {
    case TileImageKind::kColor: return "color";
    case TileImageKind::kDepth: return "depth";
    case TileImageKind::kNormal: return "normal";
    case TileImageKind::kGraph: return "graph";
  }
  return "unknown";
}

void TileImageSize(TileImageKind kind, int w, int h, int* image_w, int* image_h,
                   NormalEncoding normal_encoding) {
  const bool two_codes =
      kind == TileImageKind::kNormal && normal_encoding == NormalEncoding::kOctahedralLossy;
  *image_w = two_codes ? 2 * w : w;
  *image_h = kind == TileImageKind::kGraph ? h : 2 * h;
}

Status DepthQuantization::Check() const {
  if (!std::isfinite(near_m) || !(near_m > 0))
    return InvalidArgument("depth near_m " + std::to_string(near_m) + " must be finite and > 0");
  if (!std::isfinite(far_m) || !(far_m >= near_m))
    return InvalidArgument("depth far_m " + std::to_string(far_m) +
                           " must be finite and >= near_m " + std::to_string(near_m));
  if (far_m / near_m > 1e9)
    return InvalidArgument("depth far_m / near_m = " + std::to_string(far_m / near_m) +
                           " exceeds the limit of 1e9");
  if (bits < 8 || bits > 16)
    return InvalidArgument("depth bits " + std::to_string(bits) + " is outside [8, 16]");
  return Status::Ok();
}

double DepthQuantization::MaxRelativeError() const {
  return std::expm1(std::log(far_m / near_m) / (2.0 * (MaxCode() - 1)));
}

Status NormalQuantization::Check() const {
  if (bits < 4 || bits > 8)
    return InvalidArgument("normal bits " + std::to_string(bits) + " is outside [4, 8]");
  if (!lossy()) return Status::Ok();
  if (bits != 8) return InvalidArgument("lossy normals have 8-bit codes, not " +
                                        std::to_string(bits));
  for (const auto& [name, value] : {std::make_pair("mean_error_deg", mean_error_deg),
                                    std::make_pair("p99_error_deg", p99_error_deg)}) {
    if (!(value > 0.0 && value <= 90.0))
      return InvalidArgument(std::string("normal ") + name + " " + std::to_string(value) +
                             " is outside (0, 90]");
  }
  return Status::Ok();
}

Status TileQuantization::Check() const {
  CASUAL3D_RETURN_IF_ERROR(depth.Check());
  return normal.Check();
}

uint16_t QuantizeDepth(double depth_m, const DepthQuantization& q) {
  if (!(q.far_m > q.near_m)) return 1;
  const double d = std::fmin(q.far_m, std::fmax(q.near_m, depth_m));
  const double t = std::log(d / q.near_m) / std::log(q.far_m / q.near_m);
  const long code = 1 + std::lround(t * (q.MaxCode() - 1));
  return static_cast<uint16_t>(code < 1 ? 1 : (code > q.MaxCode() ? q.MaxCode() : code));
}

double DequantizeDepth(uint16_t code, const DepthQuantization& q) {
  if (code == 0) return 0.0;
  if (!(q.far_m > q.near_m)) return q.near_m;
  return q.near_m *
         std::exp(static_cast<double>(code - 1) / (q.MaxCode() - 1) * std::log(q.far_m / q.near_m));
}

namespace {

// The unit normal's point (u, v) on the octahedron, folded for z < 0 (sgn 0 =
// +1); false for the zero or a non-finite normal.
bool OctahedralPoint(const float normal[3], double* u, double* v) {
  const double x = normal[0], y = normal[1], z = normal[2];
  const double s = std::fabs(x) + std::fabs(y) + std::fabs(z);
  if (!(s > 0) || !std::isfinite(s)) return false;
  *u = x / s;
  *v = y / s;
  if (z < 0) {
    const double fu = (1.0 - std::fabs(*v)) * (*u >= 0 ? 1.0 : -1.0);
    const double fv = (1.0 - std::fabs(*u)) * (*v >= 0 ? 1.0 : -1.0);
    *u = fu;
    *v = fv;
  }
  return true;
}

// The unit normal of the octahedron's point (u, v) in [-1, 1]^2 (unfolded for
// z < 0, both new values from the old ones).
void NormalOfOctahedralPoint(double u, double v, float normal[3]) {
  const double z = 1.0 - std::fabs(u) - std::fabs(v);
  if (z < 0) {
    const double fu = (1.0 - std::fabs(v)) * (u >= 0 ? 1.0 : -1.0);
    const double fv = (1.0 - std::fabs(u)) * (v >= 0 ? 1.0 : -1.0);
    u = fu;
    v = fv;
  }
  const double n = std::sqrt(u * u + v * v + z * z);
  normal[0] = static_cast<float>(u / n);
  normal[1] = static_cast<float>(v / n);
  normal[2] = static_cast<float>(z / n);
}

}  // namespace

void EncodeOctahedral(const float normal[3], const NormalQuantization& q, uint8_t code[2]) {
  double u, v;
  if (!OctahedralPoint(normal, &u, &v)) {
    code[0] = code[1] = 0;
    return;
  }
  const double scale = (q.MaxCode() - 1) / 2.0;
  auto quantize = [scale](double t) {
    const long c = 1 + std::lround((std::fmin(1.0, std::fmax(-1.0, t)) + 1.0) * scale);
    return static_cast<uint8_t>(c);
  };
  code[0] = quantize(u);
  code[1] = quantize(v);
}

bool DecodeOctahedral(const uint8_t code[2], const NormalQuantization& q, float normal[3]) {
  normal[0] = normal[1] = normal[2] = 0.0f;
  if (code[0] == 0 && code[1] == 0) return true;
  if (code[0] == 0 || code[1] == 0 || code[0] > q.MaxCode() || code[1] > q.MaxCode())
    return false;
  const double scale = 2.0 / (q.MaxCode() - 1);
  NormalOfOctahedralPoint((code[0] - 1) * scale - 1.0, (code[1] - 1) * scale - 1.0, normal);
  return true;
}

bool EncodeOctahedralLossy(const float normal[3], uint8_t code[2]) {
  double u, v;
  if (!OctahedralPoint(normal, &u, &v)) {
    code[0] = code[1] = 128;
    return false;
  }
  auto quantize = [](double t) {
    return static_cast<uint8_t>(std::lround((std::fmin(1.0, std::fmax(-1.0, t)) + 1.0) * 127.5));
  };
  code[0] = quantize(u);
  code[1] = quantize(v);
  return true;
}

void DecodeOctahedralLossy(const uint8_t code[2], float normal[3]) {
  NormalOfOctahedralPoint(code[0] / 127.5 - 1.0, code[1] / 127.5 - 1.0, normal);
}

Image8 EncodeTileImage(const TwoLayerPanorama& pano, int x0, int y0, int w, int h,
                       TileImageKind kind, const TileQuantization& q) {
  int iw, ih;
  TileImageSize(kind, w, h, &iw, &ih, q.normal.type);
  if (kind == TileImageKind::kNormal && q.normal.lossy()) {
    Image8 image(iw, ih, 4, 0);
    for (int l = 0; l < kNumLayers; ++l) {
      const LayerData& L = pano.layer(l);
      for (int y = 0; y < h; ++y) {
        uint8_t* row = image.row(l * h + y);
        for (int x = 0; x < w; ++x) {
          const size_t i = pano.index(x0 + x, y0 + y);
          uint8_t code[2] = {0, 0};
          const bool lit = L.present[i] && EncodeOctahedralLossy(&L.normal[3 * i], code);
          const uint8_t alpha = L.present[i] && !lit ? 0 : 255;
          uint8_t* pu = row + 4 * x;
          uint8_t* pv = row + 4 * (w + x);
          pu[0] = pu[1] = pu[2] = code[0];
          pv[0] = pv[1] = pv[2] = code[1];
          pu[3] = pv[3] = alpha;
        }
      }
    }
    return image;
  }
  Image8 image(iw, ih, 3, 0);
  if (kind == TileImageKind::kColor) {
    for (int l = 0; l < kNumLayers; ++l)
      EncodeColorHalf(pano, l, x0, y0, w, h, image.row(l * h));
    return image;
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = pano.index(x0 + x, y0 + y);
      if (kind == TileImageKind::kGraph) {
        uint8_t* px = &image.at(x, y);
        const LayerData& F = pano.layer(kFront);
        const LayerData& B = pano.layer(kBack);
        const uint8_t kept = q.right_down_links ? kRightDownLinkBits : 0xFF;
        px[0] = F.present[i] ? F.links[i] & kept : 0;
        px[1] = B.present[i] ? B.links[i] & kept : 0;
        px[2] = static_cast<uint8_t>((F.present[i] ? kFlagFrontPresent : 0) |
                                     (B.present[i] ? kFlagBackPresent : 0) |
                                     (F.present[i] && F.label[i] ? kFlagFrontLabel : 0) |
                                     (B.present[i] && B.label[i] ? kFlagBackLabel : 0));
        continue;
      }
      for (int l = 0; l < kNumLayers; ++l) {
        const LayerData& L = pano.layer(l);
        if (!L.present[i]) continue;
        uint8_t* px = &image.at(x, l * h + y);
        if (kind == TileImageKind::kDepth) {
          const uint16_t code = QuantizeDepth(L.depth_m[i], q.depth);
          px[0] = static_cast<uint8_t>(code >> 8);
          px[1] = static_cast<uint8_t>(code & 255);
        } else {
          EncodeOctahedral(&L.normal[3 * i], q.normal, px);
        }
      }
    }
  }
  return image;
}

TileDecoder::TileDecoder(const TileQuantization& q, const ReaderChecks& checks)
    : q_(q), checks_(checks), table_(65536) {
  const int max_code = q.depth.MaxCode();
  for (int code = 0; code <= max_code; ++code)
    table_[code] = static_cast<float>(DequantizeDepth(static_cast<uint16_t>(code), q.depth));
  const float above_max = checks.on(ReaderCheck::kDepthCodeAboveMax) ? -1.0f : table_[max_code];
  std::fill(table_.begin() + max_code + 1, table_.end(), above_max);
  // Every 8-bit code pair through DecodeOctahedral once, so that decoding a
  // tile is a table look-up per pixel with exactly the same floats.
  const float invalid = checks.on(ReaderCheck::kNormalCodeInvalid)
                            ? std::numeric_limits<float>::quiet_NaN()
                            : 0.0f;
  normal_table_.resize(3 * 65536);
  for (int c0 = 0; c0 < 256; ++c0) {
    for (int c1 = 0; c1 < 256; ++c1) {
      const uint8_t code[2] = {static_cast<uint8_t>(c0), static_cast<uint8_t>(c1)};
      float* n = &normal_table_[3 * (static_cast<size_t>(c0) << 8 | c1)];
      if (q.normal.lossy())
        DecodeOctahedralLossy(code, n);
      else if (!DecodeOctahedral(code, q.normal, n))
        n[0] = n[1] = n[2] = invalid;
    }
  }
}

WebpCoding WebpContainerCoding(const uint8_t* data, size_t size) {
  auto fourcc = [data](size_t at, const char* tag) { return std::memcmp(data + at, tag, 4) == 0; };
  auto u32 = [data](size_t at) {
    return static_cast<uint32_t>(data[at]) | static_cast<uint32_t>(data[at + 1]) << 8 |
           static_cast<uint32_t>(data[at + 2]) << 16 | static_cast<uint32_t>(data[at + 3]) << 24;
  };
  if (size < 20 || !fourcc(0, "RIFF") || !fourcc(8, "WEBP")) return WebpCoding::kNotWebp;
  // Chunks end where the RIFF size says, or at the end of the bytes.
  const size_t end = std::min<uint64_t>(size, uint64_t{8} + u32(4));
  bool extended = false;
  for (size_t at = 12; at + 8 <= end;) {
    const uint64_t chunk = u32(at + 4);
    if (fourcc(at, "VP8L")) return WebpCoding::kLossless;
    if (fourcc(at, "VP8 ")) return WebpCoding::kLossy;
    if (fourcc(at, "ANIM") || fourcc(at, "ANMF")) return WebpCoding::kNotStill;
    // Only a VP8X header may come before the image chunk (ALPH, ICCP and
    // others follow it).
    if (!extended && !fourcc(at, "VP8X")) return WebpCoding::kNotWebp;
    extended = true;
    at += 8 + chunk + (chunk & 1);  // Chunks are padded to an even size.
    if (at > end) break;
  }
  return WebpCoding::kNotWebp;
}

namespace {

// The per-kind loops of DecodeTileImage for images of `kChannels` channels
// (DecodeLayerRows over the tile's rows [row_begin, row_end)). The graph loop
// returns false if some pixel has reserved flag bits (naming the first); they
// never read or write out of bounds.
template <int kChannels>
bool DecodeGraphRows(ImageView<const uint8_t> image, int x0, int y0, int w, int h,
                     bool check_reserved, TwoLayerPanorama* pano, int* bad_x, int* bad_y) {
  LayerData& F = pano->layer(kFront);
  LayerData& B = pano->layer(kBack);
  for (int y = 0; y < h; ++y) {
    const uint8_t* px = image.row(y);
    const size_t i0 = pano->index(x0, y0 + y);
    uint8_t* __restrict front_present = &F.present[i0];
    uint8_t* __restrict back_present = &B.present[i0];
    uint8_t* __restrict front_label = &F.label[i0];
    uint8_t* __restrict back_label = &B.label[i0];
    uint8_t* __restrict front_links = &F.links[i0];
    uint8_t* __restrict back_links = &B.links[i0];
    unsigned reserved = 0;
    int x = 0;
#if defined(__wasm_simd128__)
    if (kChannels == 4) {
      // 16 RGBA pixels at a time: R, G and B into their own vectors.
      const v128_t one = wasm_i8x16_splat(1);
      const v128_t reserved_bits = wasm_i8x16_splat(static_cast<int8_t>(kFlagReserved));
      v128_t bad = wasm_i8x16_splat(0);
      for (; x + 16 <= w; x += 16) {
        const uint8_t* p = px + 4 * x;
        v128_t t[4];
        for (int j = 0; j < 4; ++j) {  // RRRR GGGG BBBB AAAA of 4 pixels.
          t[j] = wasm_i8x16_shuffle(wasm_v128_load(p + 16 * j), wasm_v128_load(p + 16 * j), 0,
                                    4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15);
        }
        const v128_t rg01 = wasm_i32x4_shuffle(t[0], t[1], 0, 4, 1, 5);
        const v128_t rg23 = wasm_i32x4_shuffle(t[2], t[3], 0, 4, 1, 5);
        const v128_t ba01 = wasm_i32x4_shuffle(t[0], t[1], 2, 6, 3, 7);
        const v128_t ba23 = wasm_i32x4_shuffle(t[2], t[3], 2, 6, 3, 7);
        const v128_t r = wasm_i64x2_shuffle(rg01, rg23, 0, 2);
        const v128_t g = wasm_i64x2_shuffle(rg01, rg23, 1, 3);
        const v128_t flags = wasm_i64x2_shuffle(ba01, ba23, 0, 2);
        bad = wasm_v128_or(bad, wasm_v128_and(flags, reserved_bits));
        wasm_v128_store(front_present + x, wasm_v128_and(flags, one));
        wasm_v128_store(back_present + x, wasm_v128_and(wasm_u8x16_shr(flags, 1), one));
        wasm_v128_store(front_label + x, wasm_v128_and(wasm_u8x16_shr(flags, 2), one));
        wasm_v128_store(back_label + x, wasm_v128_and(wasm_u8x16_shr(flags, 3), one));
        wasm_v128_store(front_links + x, r);
        wasm_v128_store(back_links + x, g);
      }
      reserved |= wasm_v128_any_true(bad) ? 1u : 0u;
    }
#endif
    for (; x < w; ++x) {
      const uint8_t* p = px + kChannels * x;
      const unsigned flags = p[2];
      reserved |= flags & kFlagReserved;
      front_present[x] = static_cast<uint8_t>(flags & kFlagFrontPresent);
      back_present[x] = static_cast<uint8_t>((flags & kFlagBackPresent) >> 1);
      front_label[x] = static_cast<uint8_t>((flags & kFlagFrontLabel) >> 2);
      back_label[x] = static_cast<uint8_t>((flags & kFlagBackLabel) >> 3);
      front_links[x] = p[0];
      back_links[x] = p[1];
    }
    if (reserved && check_reserved) {  // The first offending pixel of the row, for the message.
      for (int x = 0; x < w; ++x) {
        if (px[kChannels * x + 2] & kFlagReserved) {
          *bad_x = x0 + x;
          *bad_y = y0 + y;
          return false;
        }
      }
    }
  }
  return true;
}

template <int kChannels>
void DecodeLayerRows(ImageView<const uint8_t> image, TileImageKind kind, int x0, int y0, int w,
                     int h, int row_begin, int row_end, const TileDecoder& decoder,
                     TwoLayerPanorama* pano) {
  for (int l = 0; l < kNumLayers; ++l) {
    LayerData& L = pano->layer(l);
    for (int y = row_begin; y < row_end; ++y) {
      const uint8_t* px = image.row(l * h + y);
      const size_t i0 = pano->index(x0, y0 + y);
      if (kind == TileImageKind::kColor) {
        uint8_t* rgb = &L.rgb[3 * i0];
        int x = 0;
#if defined(__wasm_simd128__)
        if (kChannels == 4) {
          // 4 RGBA pixels to 12 RGB bytes; each 16-byte store runs 4 bytes into
          // the next pixel, so the loop stops one pixel before the row's end.
          for (; x + 5 <= w; x += 4, px += 16, rgb += 12) {
            const v128_t v = wasm_v128_load(px);
            wasm_v128_store(rgb, wasm_i8x16_shuffle(v, v, 0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14,
                                                    0, 0, 0, 0));
          }
        }
#endif
        for (; x < w; ++x, px += kChannels, rgb += 3) {
          rgb[0] = px[0];
          rgb[1] = px[1];
          rgb[2] = px[2];
        }
      } else if (kind == TileImageKind::kDepth) {
        float* depth = &L.depth_m[i0];
        for (int x = 0; x < w; ++x, px += kChannels)
          depth[x] = decoder.Depth(static_cast<uint16_t>((px[0] << 8) | px[1]));
      } else if (decoder.quantization().normal.lossy()) {
        // The u codes on the left half, the v codes on the right, in G;
        // alpha below 128 marks an unlit node (the zero normal).
        float* normal = &L.normal[3 * i0];
        const uint8_t* pv = px + static_cast<size_t>(kChannels) * w;
        for (int x = 0; x < w; ++x, px += kChannels, pv += kChannels, normal += 3) {
          const uint8_t code[2] = {px[1], pv[1]};
          const float* n = decoder.Normal(code);
          const float lit = (kChannels == 4 && px[3] < 128) ? 0.0f : 1.0f;
          normal[0] = n[0] * lit;
          normal[1] = n[1] * lit;
          normal[2] = n[2] * lit;
        }
      } else {
        float* normal = &L.normal[3 * i0];
        for (int x = 0; x < w; ++x, px += kChannels, normal += 3) {
          const float* n = decoder.Normal(px);
          normal[0] = n[0];
          normal[1] = n[1];
          normal[2] = n[2];
        }
      }
    }
  }
}

}  // namespace

Status DecodeTileImage(ImageView<const uint8_t> image, TileImageKind kind, int x0, int y0, int w,
                       int h, const TileDecoder& decoder, TwoLayerPanorama* pano,
                       int num_threads) {
  if (w <= 0 || h <= 0 || x0 < 0 || y0 < 0 || x0 > pano->width() - w || y0 > pano->height() - h)
    return InvalidArgument("tile region " + std::to_string(w) + "x" + std::to_string(h) + " at " +
                           PixelName(x0, y0) + " lies outside the panorama");
  int iw, ih;
  TileImageSize(kind, w, h, &iw, &ih, decoder.quantization().normal.type);
  const bool size_ok = decoder.checks().on(ReaderCheck::kWrongTileSize)
                           ? image.width() == iw && image.height() == ih
                           : image.width() >= iw && image.height() >= ih;
  if (!size_ok)
    return InvalidData(std::string(TileImageKindName(kind)) + " image is " +
                       std::to_string(image.width()) + "x" + std::to_string(image.height()) +
                       ", expected " + std::to_string(iw) + "x" + std::to_string(ih));
  if (image.channels() != 3 && image.channels() != 4)
    return InvalidData(std::string(TileImageKindName(kind)) + " image has " +
                       std::to_string(image.channels()) + " channels, expected 3 or 4");
  const bool rgba = image.channels() == 4;
  if (kind == TileImageKind::kGraph) {
    int bad_x = 0, bad_y = 0;
    const bool check = decoder.checks().on(ReaderCheck::kReservedFlagBits);
    const bool ok = rgba ? DecodeGraphRows<4>(image, x0, y0, w, h, check, pano, &bad_x, &bad_y)
                         : DecodeGraphRows<3>(image, x0, y0, w, h, check, pano, &bad_x, &bad_y);
    if (!ok)
      return InvalidData("graph image: reserved flag bits set at pixel " + PixelName(bad_x, bad_y));
    return Status::Ok();
  }
  // Bands of rows write disjoint nodes. Colour (like the graph above) is a
  // plain byte shuffle, faster than handing a tile to other threads; depth
  // and normals go through look-up tables.
  const int threads = kind == TileImageKind::kColor ? 1 : ResolveThreads(num_threads);
  const int bands = std::min(h, threads > 1 ? 4 * threads : 1);
  ParallelFor(0, bands, threads, [&](int64_t b) {
    int64_t r0, r1;
    ChunkRange(h, bands, b, &r0, &r1);
    const int row_begin = static_cast<int>(r0), row_end = static_cast<int>(r1);
    if (rgba)
      DecodeLayerRows<4>(image, kind, x0, y0, w, h, row_begin, row_end, decoder, pano);
    else
      DecodeLayerRows<3>(image, kind, x0, y0, w, h, row_begin, row_end, decoder, pano);
  });
  return Status::Ok();
}

Status FinishDecodedPanorama(TwoLayerPanorama* pano, int num_threads, const ReaderChecks& checks,
                             DecodedNodeProblem* problem) {
  const int threads = ResolveThreads(num_threads);
  // A present node may keep depth 0 (code 0) only with its check off.
  const bool allow_no_depth = !checks.on(ReaderCheck::kPresentNodeWithoutDepth);
  for (int l = 0; l < kNumLayers; ++l) {
    LayerData& L = pano->layer(l);
    const size_t n = L.present.size();
    const uint8_t* present = L.present.data();
    // Nodes in chunks on up to `threads` threads; a chunk's runs of absent
    // nodes end at its end, and clearing a node twice changes nothing.
    const int64_t chunks = threads > 1 && n >= (size_t{1} << 16) ? 4 * threads : 1;
    // Present nodes must have a finite depth (code 0 means none, -1 marks a
    // code above the maximum; a depth range beyond 32-bit floats decodes to
    // infinity) and a valid normal code (a NaN marks an invalid one): one
    // branch-free pass, then the first offender for the message. Absent
    // nodes' values are ignored (spec/package.md Sec. 5).
    constexpr float kMaxDepth = std::numeric_limits<float>::max();
    auto node_ok = [&](size_t i) {
      const float d = L.depth_m[i];
      const bool depth_ok = (d > 0) | ((d == 0) & allow_no_depth);
      return (present[i] == 0) | (depth_ok & (d <= kMaxDepth) & (L.normal[3 * i] == L.normal[3 * i]));
    };
    std::atomic<bool> bad(false);
    ParallelFor(0, chunks, threads, [&](int64_t c) {
      int64_t begin, end;
      ChunkRange(static_cast<int64_t>(n), chunks, c, &begin, &end);
      bool chunk_ok = true;
      for (size_t i = static_cast<size_t>(begin); i < static_cast<size_t>(end); ++i)
        chunk_ok &= node_ok(i);
      if (!chunk_ok) bad.store(true, std::memory_order_relaxed);
    });
    if (bad.load()) {
      for (size_t i = 0; i < n; ++i) {
        if (node_ok(i)) continue;
        const float d = L.depth_m[i];
        const int x = static_cast<int>(i % pano->width()), y = static_cast<int>(i / pano->width());
        const bool depth_bad = !(d > 0 && d <= kMaxDepth) && !(d == 0 && allow_no_depth);
        if (problem != nullptr)
          *problem = {x, y, l, depth_bad ? TileImageKind::kDepth : TileImageKind::kNormal};
        const std::string node = std::string(l == kFront ? "front" : "back") +
                                 " node at pixel " + PixelName(x, y);
        if (!depth_bad)
          return InvalidData(node + " has an invalid octahedral normal code (one 0 or above "
                                    "2^bits - 1)");
        return InvalidData(node + (d > 0    ? " has a depth beyond the range of 32-bit floats (the "
                                              "manifest's depth range is too large)"
                                   : d == 0 ? " has no depth (code 0)"
                                            : " has a depth code above the maximum 2^bits - 1"));
      }
    }
    // Every field of an absent node becomes zero: runs of absent nodes are
    // found eight flags at a time and cleared array by array.
    auto clear = [&L](size_t begin, size_t end) {
      const size_t k = end - begin;
      std::memset(&L.depth_m[begin], 0, k * sizeof(float));
      std::memset(&L.label[begin], 0, k);
      std::memset(&L.links[begin], 0, k);
      std::memset(&L.rgb[3 * begin], 0, 3 * k);
      std::memset(&L.normal[3 * begin], 0, 3 * k * sizeof(float));
    };
    // The 8 present flags from i, which are 0 or 1 (graph decoding).
    auto flags_at = [present](size_t i) {
      uint64_t word;
      std::memcpy(&word, present + i, sizeof(word));
      return word;
    };
    constexpr uint64_t kAllPresent = 0x0101010101010101ull;
    ParallelFor(0, chunks, threads, [&](int64_t c) {
      int64_t chunk_begin, chunk_end;
      ChunkRange(static_cast<int64_t>(n), chunks, c, &chunk_begin, &chunk_end);
      const size_t stop = static_cast<size_t>(chunk_end);
      size_t i = static_cast<size_t>(chunk_begin);
      while (i < stop) {
        // Skip present nodes.
        while (i + 8 <= stop && flags_at(i) == kAllPresent) i += 8;
        while (i < stop && present[i]) ++i;
        if (i == stop) break;
        size_t end = i + 1;
        while (end + 8 <= stop && flags_at(end) == 0) end += 8;
        while (end < stop && !present[end]) ++end;
        clear(i, end);
        i = end;
      }
    });
  }
  return Status::Ok();
}

namespace {

// Which node of a pixel links into a node of layer `into` along one
// direction, given the two nodes' links in that direction: the front one,
// else the back one, else none.
inline Link FromWhich(Link front, Link back, Link into) {
  return front == into ? Link::kFront : back == into ? Link::kBack : Link::kNone;
}

}  // namespace

Status CompleteLinks(TwoLayerPanorama* pano, const ReaderChecks& checks,
                     DecodedNodeProblem* problem) {
  const int width = pano->width(), height = pano->height();
  uint8_t* links[kNumLayers] = {pano->layer(kFront).links.data(), pano->layer(kBack).links.data()};
  const uint8_t* present[kNumLayers] = {pano->layer(kFront).present.data(),
                                        pano->layer(kBack).present.data()};
  const bool refuse = checks.on(ReaderCheck::kLeftUpLinkBits);
  // Node (x, y) of layer m: its left link from the right links of pixel
  // x - 1 (wrapping), its up link from the down links of row y - 1. Only
  // right and down links are read and only left and up ones written, so one
  // pass in place reads what it needs whatever it has written; a node's own
  // left and up bits are looked at before they are written.
  for (int y = 0; y < height; ++y) {
    const size_t row = static_cast<size_t>(y) * width;
    for (int x = 0; x < width; ++x) {
      const size_t i = row + x;
      const size_t left = row + (x == 0 ? width - 1 : x - 1);
      const Link front_right = GetLink(links[kFront][left], kRight);
      const Link back_right = GetLink(links[kBack][left], kRight);
      const Link front_down = y > 0 ? GetLink(links[kFront][i - width], kDown) : Link::kNone;
      const Link back_down = y > 0 ? GetLink(links[kBack][i - width], kDown) : Link::kNone;
      for (int m = 0; m < kNumLayers; ++m) {
        if (!present[m][i]) continue;  // Absent nodes hold no links (FinishDecodedPanorama).
        uint8_t stored = links[m][i];
        if ((stored & ~kRightDownLinkBits & 0xFF) != 0) {
          if (refuse) {
            if (problem != nullptr) {
              problem->x = x;
              problem->y = y;
              problem->layer = m;
              problem->kind = TileImageKind::kGraph;
            }
            return InvalidData(std::string("graph image: ") + (m == kFront ? "front" : "back") +
                               " node at pixel " + PixelName(x, y) +
                               " has left or up link bits set (this version stores right and "
                               "down links only)");
          }
          stored &= kRightDownLinkBits;
        }
        const Link into = m == kFront ? Link::kFront : Link::kBack;
        stored = SetLink(stored, kLeft, FromWhich(front_right, back_right, into));
        links[m][i] = SetLink(stored, kUp, FromWhich(front_down, back_down, into));
      }
    }
  }
  return Status::Ok();
}

}  // namespace casual3d
