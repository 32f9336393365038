#include "reconstruct/io/heif_io.h"

#include <libheif/heif.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/io/jpeg_exif.h"

namespace casual3d::io {
namespace {

heif_error AppendToString(heif_context*, const void* data, size_t size, void* out) {
  static_cast<std::string*>(out)->append(static_cast<const char*>(data), size);
  return {heif_error_Ok, heif_suberror_Unspecified, "ok"};
}

// The red channel's value at (x, y) of the test pattern, in [0, 1].
double Pattern(int x, int y, int c) {
  return c == 0 ? x / 63.0 : c == 1 ? y / 47.0 : 0.5 + 0.3 * std::sin(0.15 * (x + y));
}

// A 64x48 HEIC of Pattern() at `bits` per channel, written by libheif's
// encoder, with `exif` (an APP1 payload, "Exif\0\0" + TIFF) as metadata if not empty.
std::string EncodeHeic(int bits, const std::string& exif) {
  const int w = 64, h = 48;
  heif_context* ctx = heif_context_alloc();
  heif_encoder* encoder = nullptr;
  EXPECT_EQ(heif_context_get_encoder_for_format(ctx, heif_compression_HEVC, &encoder).code,
            heif_error_Ok);
  heif_encoder_set_lossy_quality(encoder, 95);
  heif_image* image = nullptr;
  heif_image_create(w, h, heif_colorspace_RGB,
                    bits > 8 ? heif_chroma_interleaved_RRGGBB_LE : heif_chroma_interleaved_RGB,
                    &image);
  heif_image_add_plane(image, heif_channel_interleaved, w, h, bits);
  int stride = 0;
  uint8_t* plane = heif_image_get_plane(image, heif_channel_interleaved, &stride);
  const int max_value = (1 << bits) - 1;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        const int v = static_cast<int>(std::lround(Pattern(x, y, c) * max_value));
        if (bits > 8) {
          plane[y * stride + (x * 3 + c) * 2] = v & 0xFF;
          plane[y * stride + (x * 3 + c) * 2 + 1] = v >> 8;
        } else {
          plane[y * stride + x * 3 + c] = static_cast<uint8_t>(v);
        }
      }
    }
  }
  heif_image_handle* handle = nullptr;
  EXPECT_EQ(heif_context_encode_image(ctx, image, encoder, nullptr, &handle).code, heif_error_Ok);
  if (!exif.empty()) {
    EXPECT_EQ(heif_context_add_exif_metadata(ctx, handle, exif.data(), static_cast<int>(exif.size())).code,
              heif_error_Ok);
  }
  std::string bytes;
  heif_writer writer{1, &AppendToString};
  EXPECT_EQ(heif_context_write(ctx, &writer, &bytes).code, heif_error_Ok);
  heif_image_handle_release(handle);
  heif_image_release(image);
  heif_encoder_release(encoder);
  heif_context_free(ctx);
  return bytes;
}

double MeanAbsError(const Image8& image) {
  double sum = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < 3; ++c) sum += std::abs(image.at(x, y, c) - Pattern(x, y, c) * 255.0);
  return sum / (image.width() * image.height() * 3.0);
}

TEST(HeifIoTest, EightBitHeicDecodesToRgb) {
  const std::string bytes = EncodeHeic(8, "");
  ASSERT_TRUE(LooksLikeHeif(bytes));
  DecodedImageInfo info;
  const Image8 image = DecodeImage(bytes, "a.heic", {}, &info);
  EXPECT_EQ(info.format, "heif");
  ASSERT_EQ(image.width(), 64);
  ASSERT_EQ(image.height(), 48);
  // Red grows with x and green with y: a channel swap or a wrong stride fails.
  EXPECT_LT(MeanAbsError(image), 4.0);
  EXPECT_GT(image.at(63, 0, 0), 240);
  EXPECT_LT(image.at(0, 0, 0), 15);
  EXPECT_TRUE(HeifExifTiff(bytes).empty());
}

TEST(HeifIoTest, TenBitHeicIsScaledToEightBits) {
  const std::string bytes = EncodeHeic(10, "");
  HeifImageInfo info;
  const Image8 image = DecodeHeif(bytes, "b.heic", 32768, &info);
  EXPECT_EQ(info.bits_per_channel, 10);
  // Unscaled 10-bit values would wrap or saturate: the error would be huge.
  EXPECT_LT(MeanAbsError(image), 4.0);
}

TEST(HeifIoTest, ExifBlockIsFound) {
  ExifFields fields;
  fields.make = "Apple";
  fields.model = "iPhone 12";
  fields.focal_mm = 4.2;
  const std::string jpeg = InsertExif(std::string("\xFF\xD8\xFF\xD9", 4), fields);
  const size_t length = (static_cast<uint8_t>(jpeg[4]) << 8) | static_cast<uint8_t>(jpeg[5]);
  const std::string app1 = jpeg.substr(6, length - 2);  // "Exif\0\0" + TIFF.
  const std::string tiff = HeifExifTiff(EncodeHeic(8, app1));
  ASSERT_GE(tiff.size(), 8u);
  EXPECT_EQ(tiff, app1.substr(6));
}

TEST(HeifIoTest, BrokenHeifIsNamed) {
  std::string bytes = EncodeHeic(8, "");
  bytes.resize(bytes.size() / 2);
  try {
    DecodeImage(bytes, "photos/IMG_1.HEIC");
    FAIL() << "no error";
  } catch (const IoException& e) {
    EXPECT_NE(std::string(e.what()).find("photos/IMG_1.HEIC"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(LooksLikeHeif("not a heif file"));
}

}  // namespace
}  // namespace casual3d::io
