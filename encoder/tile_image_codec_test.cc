#include "encoder/tile_image_codec.h"

#include <gtest/gtest.h>

#include "encoder/package_writer.h"
#include "format/file_source.h"
#include "format/package_test_scene.h"
#include "format/single_file.h"

namespace casual3d::encoder {
namespace {

// A format this build has no codec for.
const TileImageFormat kUnknown = {"avif", "AVIF", ".avif", "image/avif", nullptr};

Image8 Pattern(int w, int h) {
  Image8 image(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = static_cast<uint8_t>(x * 5 + y * 3 + c * 70);
  return image;
}

// The packages written today are 1.x: their tiles are WebP, read and written
// by the WebP codec.
TEST(TileImageCodecTest, PackagesOfVersionOneUseTheWebpCodec) {
  Manifest manifest;
  manifest.version_minor = 1;
  StatusOr<const TileImageFormat*> format = TileImageFormatOf(manifest);
  ASSERT_TRUE(format.ok()) << format.status().ToString();
  StatusOr<const TileImageCodec*> codec = TileImageCodecFor(**format);
  ASSERT_TRUE(codec.ok()) << codec.status().ToString();
  EXPECT_STREQ((*codec)->format().name, "webp");
  StatusOr<const ImageDecoder*> decoder = TileImageDecoders().DecoderFor(**format);
  ASSERT_TRUE(decoder.ok());
  EXPECT_EQ(*decoder, static_cast<const ImageDecoder*>(*codec));
}

TEST(TileImageCodecTest, LosslessRoundTripIsExactAndPassesTheLosslessCheck) {
  const TileImageCodec& codec = **TileImageCodecFor(WebpTileImageFormat());
  const Image8 image = Pattern(40, 24);
  TileEncodeSettings lossless;
  lossless.lossless = true;
  StatusOr<std::vector<uint8_t>> bytes = codec.Encode(image.view(), lossless);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  EXPECT_TRUE(codec.format().check_lossless("a.webp", "depth", bytes->data(), bytes->size()).ok());
  StatusOr<Image8> decoded = codec.Decode(bytes->data(), bytes->size());
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  EXPECT_TRUE(*decoded == image);

  StatusOr<std::vector<uint8_t>> lossy = codec.Encode(image.view(), TileEncodeSettings());
  ASSERT_TRUE(lossy.ok());
  const Status refused = codec.format().check_lossless("l0/0-0.depth.webp", "depth",
                                                       lossy->data(), lossy->size());
  EXPECT_EQ(refused.code(), StatusCode::kInvalidData);
  EXPECT_EQ(refused.message(),
            "l0/0-0.depth.webp: a depth image must be lossless WebP (VP8L); this one is lossy "
            "(VP8)");
}

TEST(TileImageCodecTest, UnknownFormatIsAClearError) {
  StatusOr<const TileImageCodec*> codec = TileImageCodecFor(kUnknown);
  EXPECT_EQ(codec.status().code(), StatusCode::kNotFound);
  EXPECT_EQ(codec.status().message(), "no codec for AVIF tile images (\"avif\") in this build");
  EXPECT_EQ(TileImageDecoders().DecoderFor(kUnknown).status().message(),
            codec.status().message());
}

// ReadPackage decodes with the decoder the factory gives for the manifest's
// format, and reports a factory without one before reading any tile.
TEST(TileImageCodecTest, ReadPackageTakesTheDecoderOfTheManifestsFormat) {
  PackageOptions options;
  options.tile_size = 64;
  options.levels = 1;
  const TwoLayerPanorama pano = casual3d::testing::MakePackageTestPanorama(128, 64);
  StatusOr<PackageFiles> files = EncodePackage(pano, options);
  ASSERT_TRUE(files.ok()) << files.status().ToString();
  StatusOr<std::vector<uint8_t>> bytes = BuildSingleFile(*files);
  ASSERT_TRUE(bytes.ok());
  StatusOr<std::unique_ptr<SingleFileSource>> source = SingleFileSource::Create(*bytes);
  ASSERT_TRUE(source.ok());

  StatusOr<TwoLayerPanorama> read = ReadPackage(**source, TileImageDecoders());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->width(), 128);

  class NoDecoders : public ImageDecoderFactory {
   public:
    StatusOr<const ImageDecoder*> DecoderFor(const TileImageFormat& format) const override {
      return NotFound(std::string("no decoder for ") + format.name);
    }
  };
  EXPECT_EQ(ReadPackage(**source, NoDecoders()).status().message(), "no decoder for webp");
}

}  // namespace
}  // namespace casual3d::encoder
