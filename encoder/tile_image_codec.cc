#include "encoder/tile_image_codec.h"

#include <string>

#include "encoder/webp_codec.h"

namespace casual3d::encoder {
namespace {

class WebpTileCodec : public TileImageCodec {
 public:
  const TileImageFormat& format() const override { return WebpTileImageFormat(); }
  StatusOr<Image8> Decode(const uint8_t* data, size_t size) const override {
    return DecodeWebp(data, size);
  }
  StatusOr<std::vector<uint8_t>> Encode(ImageView<const uint8_t> rgb,
                                        const TileEncodeSettings& settings) const override {
    WebpEncodeOptions webp;
    webp.lossless = settings.lossless;
    webp.quality = settings.quality;
    webp.method = settings.method;
    return EncodeWebp(rgb, webp);
  }
};

class CodecDecoders : public ImageDecoderFactory {
 public:
  StatusOr<const ImageDecoder*> DecoderFor(const TileImageFormat& format) const override {
    CASUAL3D_ASSIGN_OR_RETURN(const TileImageCodec* codec, TileImageCodecFor(format));
    return static_cast<const ImageDecoder*>(codec);
  }
};

}  // namespace

StatusOr<const TileImageCodec*> TileImageCodecFor(const TileImageFormat& format) {
  static const WebpTileCodec webp;
  if (std::string(format.name) == webp.format().name) return &webp;
  return NotFound(std::string("no codec for ") + format.label + " tile images (\"" + format.name +
                  "\") in this build");
}

const ImageDecoderFactory& TileImageDecoders() {
  static const CodecDecoders decoders;
  return decoders;
}

}  // namespace casual3d::encoder
