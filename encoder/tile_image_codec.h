#pragma once

// The native codecs of package tile images, behind one seam: a writer or
// reader asks for the codec of a TileImageFormat (format/tile_image_format.h,
// chosen from the manifest) and never names the format itself. Adding a tile
// image format is its TileImageFormat, its codec here and their tests.

#include <cstdint>
#include <vector>

#include "format/image.h"
#include "format/package_reader.h"
#include "format/status.h"
#include "format/tile_image_format.h"

namespace casual3d::encoder {

// How to encode one tile image.
struct TileEncodeSettings {
  // Every value kept exactly (depth, normal and graph images).
  bool lossless = false;
  // Lossy: quality 0..100 (higher is better and larger). Lossless: effort
  // 0..100 (higher is smaller and slower).
  float quality = 90.0f;
  // Speed/size trade-off 0 (fastest) .. 6 (smallest).
  int method = 4;
};

// Encoder and decoder of one tile image format. Thread-safe.
class TileImageCodec : public ImageDecoder {
 public:
  virtual const TileImageFormat& format() const = 0;
  // Encodes a 3-channel (RGB) tile image.
  virtual StatusOr<std::vector<uint8_t>> Encode(ImageView<const uint8_t> rgb,
                                                const TileEncodeSettings& settings) const = 0;
};

// The codec of `format`; kNotFound naming the format when this build has none.
StatusOr<const TileImageCodec*> TileImageCodecFor(const TileImageFormat& format);

// The decoders of TileImageCodecFor, for ReadPackage: the reader picks the
// one of the package's format.
const ImageDecoderFactory& TileImageDecoders();

}  // namespace casual3d::encoder
