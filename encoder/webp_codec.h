#pragma once

// WebP encoding and decoding with libwebp: the tile images of a package.
// The decoder implements format/'s ImageDecoder interface for native tools.

#include <cstdint>
#include <vector>

#include "format/image.h"
#include "format/package_reader.h"
#include "format/status.h"

namespace casual3d::encoder {

// The WebP format limit on either side, pixels.
constexpr int kMaxWebpDimension = 16383;

struct WebpEncodeOptions {
  bool lossless = false;
  // Lossy: quality 0..100 (higher is better and larger). Lossless: effort
  // 0..100 (higher is smaller and slower); the pixels are exact either way.
  float quality = 90.0f;
  // Speed/size trade-off 0 (fastest) .. 6 (smallest).
  int method = 4;
  // Lossy only: sharper RGB->YUV conversion (better colour edges, slower).
  bool sharp_yuv = true;

  Status Check() const;
};

// Encodes a 3-channel (RGB) or 4-channel (RGBA) image. Lossless encodings keep
// every value exactly; lossy ones keep alpha exactly (it is coded losslessly)
// and the colour under any alpha (tile images carry data).
StatusOr<std::vector<uint8_t>> EncodeWebp(ImageView<const uint8_t> rgb,
                                          const WebpEncodeOptions& options);

// Decodes WebP bytes to a 3-channel RGB image, or RGBA when the image has
// alpha. Untrusted input: returns kInvalidData for anything that is not a
// decodable WebP image and kLimitExceeded above kMaxWebpDimension or
// `max_pixels` pixels.
StatusOr<Image8> DecodeWebp(const uint8_t* data, size_t size,
                            int64_t max_pixels = int64_t{1} << 26);

// ImageDecoder over DecodeWebp (thread-safe).
class WebpImageDecoder : public ImageDecoder {
 public:
  StatusOr<Image8> Decode(const uint8_t* data, size_t size) const override {
    return DecodeWebp(data, size);
  }
};

}  // namespace casual3d::encoder
