// Fuzz target (format/fuzz/CMakeLists.txt): DecodeTileImage of a raw image
// whose size, kind, quantization, checks and pixels come from the input, then FinishDecodedPanorama and
// TwoLayerPanorama::Validate; and WebpContainerCoding of the input's bytes.

#include <algorithm>

#include "format/tile_codec.h"

namespace casual3d::fuzz {
namespace {

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
  ReaderChecks checks;
  if ((data[6] >> 2) < kNumReaderChecks) checks.Disable(static_cast<ReaderCheck>(data[6] >> 2));
  const TileDecoder decoder(q, checks);
  const Image8& const_image = image;
  Status s = DecodeTileImage(const_image.view(), kind, 8, 4, w, h, decoder, &pano);
  if (s.ok() && FinishDecodedPanorama(&pano, 1, checks).ok()) (void)pano.Validate();
  return 0;
}

}  // namespace
}  // namespace casual3d::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return casual3d::fuzz::FuzzTileDecode(data, size);
}
