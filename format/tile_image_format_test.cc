#include "format/tile_image_format.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace casual3d {
namespace {

// The smallest RIFF container with one image chunk `fourcc` of 10 bytes.
std::vector<uint8_t> WebpFile(const char* fourcc) {
  const std::string file = std::string("RIFF\x16\0\0\0WEBP", 12) + fourcc +
                           std::string("\x0a\0\0\0", 4) + std::string(10, '\0');
  return std::vector<uint8_t>(file.begin(), file.end());
}

TEST(TileImageFormatTest, PackagesOfVersionOneHoldWebp) {
  StatusOr<const TileImageFormat*> format = TileImageFormatForVersion(1);
  ASSERT_TRUE(format.ok());
  EXPECT_EQ(*format, &WebpTileImageFormat());
  EXPECT_STREQ((*format)->name, "webp");
  EXPECT_STREQ((*format)->extension, ".webp");
  EXPECT_STREQ((*format)->mime_type, "image/webp");
  Manifest manifest;
  EXPECT_EQ(*TileImageFormatOf(manifest), &WebpTileImageFormat());
}

TEST(TileImageFormatTest, UnknownVersionOrNameIsAClearError) {
  EXPECT_EQ(*TileImageFormatForVersion(2), &WebpTileImageFormat());
  const Status version = TileImageFormatForVersion(3).status();
  EXPECT_EQ(version.code(), StatusCode::kUnsupportedVersion);
  EXPECT_EQ(version.message(), "packages of major version 3 have no known tile image format "
                               "(1.x and 2.x: WebP)");
  EXPECT_EQ(*FindTileImageFormat("webp"), &WebpTileImageFormat());
  const Status name = FindTileImageFormat("avif").status();
  EXPECT_EQ(name.code(), StatusCode::kNotFound);
  EXPECT_EQ(name.message(), "no tile image format \"avif\" (known: webp)");
}

TEST(TileImageFormatTest, ExtensionGivesTheFormat) {
  EXPECT_EQ(TileImageFormatByExtension(".webp"), &WebpTileImageFormat());
  EXPECT_EQ(TileImageFormatByExtension(".png"), nullptr);
}

TEST(TileImageFormatTest, TileFileNamesFollowTheSpec) {
  EXPECT_EQ(TileFileName(0, 1, 3, TileImageKind::kGraph, WebpTileImageFormat()),
            "l0/1-3.graph.webp");
  EXPECT_EQ(TileFileName(2, 0, 0, TileImageKind::kColor, WebpTileImageFormat()),
            "l2/0-0.color.webp");
}

TEST(TileImageFormatTest, WebpLosslessCheckNamesTheFileAndTheCoding) {
  const TileImageFormat& webp = WebpTileImageFormat();
  const std::vector<uint8_t> lossless = WebpFile("VP8L"), lossy = WebpFile("VP8 ");
  EXPECT_TRUE(webp.check_lossless("a", "graph", lossless.data(), lossless.size()).ok());
  const Status s = webp.check_lossless("l0/0-1.normal.webp", "normal", lossy.data(), lossy.size());
  EXPECT_EQ(s.code(), StatusCode::kInvalidData);
  EXPECT_EQ(s.message(),
            "l0/0-1.normal.webp: a normal image must be lossless WebP (VP8L); this one is lossy "
            "(VP8)");
  // A malformed container is left to the decoder.
  const uint8_t junk[] = {1, 2, 3};
  EXPECT_TRUE(webp.check_lossless("a", "depth", junk, sizeof(junk)).ok());
}

}  // namespace
}  // namespace casual3d
