#include "encoder/webp_codec.h"

#include <string>

#include <webp/decode.h>
#include <webp/encode.h>

namespace casual3d::encoder {

Status WebpEncodeOptions::Check() const {
  if (!(quality >= 0.0f && quality <= 100.0f))
    return InvalidArgument("WebP quality " + std::to_string(quality) + " is outside [0, 100]");
  if (method < 0 || method > 6)
    return InvalidArgument("WebP method " + std::to_string(method) + " is outside [0, 6]");
  return Status::Ok();
}

StatusOr<std::vector<uint8_t>> EncodeWebp(ImageView<const uint8_t> rgb,
                                          const WebpEncodeOptions& options) {
  CASUAL3D_RETURN_IF_ERROR(options.Check());
  if (rgb.channels() != 3 && rgb.channels() != 4)
    return InvalidArgument("EncodeWebp needs a 3- or 4-channel image");
  if (rgb.width() < 1 || rgb.height() < 1 || rgb.width() > kMaxWebpDimension ||
      rgb.height() > kMaxWebpDimension)
    return InvalidArgument("image size " + std::to_string(rgb.width()) + "x" +
                           std::to_string(rgb.height()) + " is outside the WebP limit of " +
                           std::to_string(kMaxWebpDimension));
  WebPConfig config;
  if (!WebPConfigInit(&config)) return InternalError("libwebp version mismatch");
  config.lossless = options.lossless ? 1 : 0;
  config.quality = options.quality;
  config.method = options.method;
  // Keep the values under any alpha: tile images carry data, not pictures.
  config.exact = 1;
  config.use_sharp_yuv = (!options.lossless && options.sharp_yuv) ? 1 : 0;
  if (!WebPValidateConfig(&config)) return InvalidArgument("invalid WebP configuration");

  WebPPicture picture;
  if (!WebPPictureInit(&picture)) return InternalError("libwebp version mismatch");
  picture.width = rgb.width();
  picture.height = rgb.height();
  picture.use_argb = options.lossless ? 1 : 0;
  const int imported =
      rgb.channels() == 4
          ? WebPPictureImportRGBA(&picture, rgb.data(), static_cast<int>(rgb.stride()))
          : WebPPictureImportRGB(&picture, rgb.data(), static_cast<int>(rgb.stride()));
  if (!imported) {
    WebPPictureFree(&picture);
    return InternalError("WebP: out of memory importing a " + std::to_string(rgb.width()) + "x" +
                         std::to_string(rgb.height()) + " image");
  }
  WebPMemoryWriter writer;
  WebPMemoryWriterInit(&writer);
  picture.writer = WebPMemoryWrite;
  picture.custom_ptr = &writer;
  const int ok = WebPEncode(&config, &picture);
  const int error = picture.error_code;
  WebPPictureFree(&picture);
  if (!ok) {
    WebPMemoryWriterClear(&writer);
    return InternalError("WebP encoding failed (libwebp error " + std::to_string(error) + ")");
  }
  std::vector<uint8_t> bytes(writer.mem, writer.mem + writer.size);
  WebPMemoryWriterClear(&writer);
  return bytes;
}

StatusOr<Image8> DecodeWebp(const uint8_t* data, size_t size, int64_t max_pixels) {
  // One parse of the headers: the size and whether there is alpha.
  WebPBitstreamFeatures features;
  if (data == nullptr || size == 0 || WebPGetFeatures(data, size, &features) != VP8_STATUS_OK)
    return InvalidData("not a WebP image");
  const int width = features.width, height = features.height;
  if (width < 1 || height < 1 || width > kMaxWebpDimension || height > kMaxWebpDimension ||
      static_cast<int64_t>(width) * height > max_pixels)
    return LimitExceeded("WebP image of " + std::to_string(width) + "x" + std::to_string(height) +
                         " exceeds the limit");
  const int channels = features.has_alpha ? 4 : 3;
  Image8 image(width, height, channels);
  const uint8_t* decoded =
      channels == 4 ? WebPDecodeRGBAInto(data, size, image.data(), image.size(), width * 4)
                    : WebPDecodeRGBInto(data, size, image.data(), image.size(), width * 3);
  if (decoded == nullptr)
    return InvalidData("WebP image of " + std::to_string(width) + "x" + std::to_string(height) +
                       " is truncated or corrupt");
  return image;
}

}  // namespace casual3d::encoder
