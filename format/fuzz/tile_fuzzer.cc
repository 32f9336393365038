// Fuzz target (format/fuzz/CMakeLists.txt): DecodeTileImage of a raw image
// whose size, kind, quantization, checks and pixels come from the input, then FinishDecodedPanorama
// and TwoLayerPanorama::Validate (and ValidateLinks, where it finds a wrong link); and
// WebpContainerCoding of the input's bytes.

#include <algorithm>
#include <map>
#include <memory>
#include <tuple>

#include "format/tile_codec.h"

namespace casual3d::fuzz {
namespace {

// The decoder of (depth bits, normal bits, check switched off, or
// kNumReaderChecks for none). Building one fills two tables of 65536
// entries, which took most of each input's time (about 60 inputs a second
// under the sanitizers); a decoder is immutable, so the last 64 built are
// kept (at most 64 MB).
const TileDecoder& CachedDecoder(const TileQuantization& q, int check_off) {
  static std::map<std::tuple<int, int, int>, std::unique_ptr<TileDecoder>> cache;
  const auto key = std::make_tuple(q.depth.bits, q.normal.bits, check_off);
  auto it = cache.find(key);
  if (it == cache.end()) {
    if (cache.size() >= 64) cache.clear();
    ReaderChecks checks;
    if (check_off < kNumReaderChecks) checks.Disable(static_cast<ReaderCheck>(check_off));
    it = cache.emplace(key, std::make_unique<TileDecoder>(q, checks)).first;
  }
  return *it->second;
}

// Input layout: byte 0 kind (mod 4), byte 1 tile width 1..32, byte 2 tile
// height 1..32, byte 3 channels (3 or 4), byte 4 depth bits, byte 5 normal
// bits, byte 6 image width delta (bits 0-1) and a check to switch off (bits
// 2-7, none above kNumReaderChecks), then pixels (zero-padded).
int FuzzTileDecode(const uint8_t* data, size_t size) {
  (void)WebpContainerCoding(data, size);
  if (size < 7) return 0;
  const TileImageKind kind = static_cast<TileImageKind>(data[0] % kNumTileImageKinds);
  const int w = 1 + data[1] % 32, h = 1 + data[2] % 32;
  const int channels = 3 + (data[3] & 1);
  TileQuantization q;
  q.depth.near_m = 0.5;
  q.depth.far_m = 80.0;
  q.depth.bits = 8 + data[4] % 9;
  q.normal.bits = 4 + data[5] % 5;
  int iw, ih;
  TileImageSize(kind, w, h, &iw, &ih);
  iw += (data[6] & 3) == 3 ? 1 : 0;  // Sometimes a wrong size.
  Image8 image(iw, ih, channels, 0);
  std::copy_n(data + 7, std::min(size - 7, image.size()), image.data());
  TwoLayerPanorama pano(48, 40);
  const int check_off = std::min(data[6] >> 2, kNumReaderChecks);
  const TileDecoder& decoder = CachedDecoder(q, check_off);
  const ReaderChecks& checks = decoder.checks();
  const Image8& const_image = image;
  // At the panorama's left column and top row too (the seam and row 0 of
  // CompleteLinks), from bits 6 and 7 of byte 5.
  const int x0 = (data[5] & 0x40) ? 0 : 8, y0 = (data[5] & 0x80) ? 0 : 4;
  Status s = DecodeTileImage(const_image.view(), kind, x0, y0, w, h, decoder, &pano);
  if (!s.ok() || !FinishDecodedPanorama(&pano, 1, checks).ok()) return 0;
  // Version 2.x graph images (right and down links only) when byte 4 is odd.
  if (kind == TileImageKind::kGraph && (data[4] & 1) != 0) {
    DecodedNodeProblem problem;
    if (!CompleteLinks(&pano, checks, &problem).ok()) {
      if (problem.x < 0 || problem.x >= pano.width() || problem.y < 0 || problem.y >= pano.height())
        __builtin_trap();
      return 0;
    }
  }
  (void)pano.Validate();
  // PackageReader names the graph images of a wrong link from where
  // ValidateLinks found it: the node and the pixel it points at lie inside.
  NodeProblem where;
  if (!pano.ValidateLinks(1, &where).ok() && where.link) {
    auto inside = [&](int x, int y) {
      return x >= 0 && x < pano.width() && y >= 0 && y < pano.height();
    };
    if (!inside(where.x, where.y) ||
        (where.target_x >= 0 && !inside(where.target_x, where.target_y)))
      __builtin_trap();
  }
  return 0;
}

}  // namespace
}  // namespace casual3d::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return casual3d::fuzz::FuzzTileDecode(data, size);
}
