#include "encoder/webp_codec.h"

#include <cmath>

#include <gtest/gtest.h>

namespace casual3d::encoder {
namespace {

Image8 Pattern(int w, int h) {
  Image8 image(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      image.at(x, y, 0) = static_cast<uint8_t>(x * 7 + y);
      image.at(x, y, 1) = static_cast<uint8_t>(128 + 100 * std::sin(x * 0.05) * std::cos(y * 0.07));
      image.at(x, y, 2) = static_cast<uint8_t>((x ^ y) & 0xFF);
    }
  return image;
}

TEST(WebpCodecTest, LosslessRoundTripIsExact) {
  const Image8 image = Pattern(123, 77);
  WebpEncodeOptions options;
  options.lossless = true;
  options.quality = 25;
  options.method = 1;
  StatusOr<std::vector<uint8_t>> bytes = EncodeWebp(image.view(), options);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  StatusOr<Image8> decoded = DecodeWebp(bytes->data(), bytes->size());
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  EXPECT_TRUE(*decoded == image);
}

TEST(WebpCodecTest, LossyKeepsSmoothImagesClose) {
  Image8 image(256, 128, 3);
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 256; ++x)
      for (int c = 0; c < 3; ++c)
        image.at(x, y, c) = static_cast<uint8_t>(128 + 90 * std::sin(x * 0.03 + c) * std::cos(y * 0.05));
  const Image8& source = image;
  StatusOr<std::vector<uint8_t>> bytes = EncodeWebp(source.view(), WebpEncodeOptions());
  ASSERT_TRUE(bytes.ok());
  StatusOr<Image8> decoded = DecodeWebp(bytes->data(), bytes->size());
  ASSERT_TRUE(decoded.ok());
  double se = 0;
  for (size_t i = 0; i < image.size(); ++i) {
    const double d = double(image.data()[i]) - decoded->data()[i];
    se += d * d;
  }
  const double psnr = 10 * std::log10(255.0 * 255.0 / (se / image.size()));
  EXPECT_GT(psnr, 40.0);
  EXPECT_LT(bytes->size(), image.size() / 4);
}

TEST(WebpCodecTest, RejectsBadInput) {
  const uint8_t garbage[] = {'R', 'I', 'F', 'F', 1, 2, 3, 4, 'W', 'E', 'B', 'P', 0, 0};
  EXPECT_EQ(DecodeWebp(garbage, sizeof(garbage)).status().code(), StatusCode::kInvalidData);
  EXPECT_EQ(DecodeWebp(nullptr, 0).status().code(), StatusCode::kInvalidData);
  const Image8 image = Pattern(64, 64);
  WebpEncodeOptions lossless;
  lossless.lossless = true;
  std::vector<uint8_t> bytes = *EncodeWebp(image.view(), lossless);
  for (size_t keep : {size_t{20}, size_t{40}, bytes.size() / 2, bytes.size() - 1}) {
    EXPECT_FALSE(DecodeWebp(bytes.data(), keep).ok()) << "truncated to " << keep;
  }
  WebpEncodeOptions bad;
  bad.quality = 120;
  EXPECT_EQ(EncodeWebp(image.view(), bad).status().code(), StatusCode::kInvalidArgument);
  const Image8 gray(8, 8, 1);
  EXPECT_EQ(EncodeWebp(gray.view(), WebpEncodeOptions()).status().code(),
            StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace casual3d::encoder
