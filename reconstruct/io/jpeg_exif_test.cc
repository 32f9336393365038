#include "reconstruct/io/jpeg_exif.h"

#include <gtest/gtest.h>

#include "reconstruct/io/image_io.h"

namespace casual3d::io {
namespace {

TEST(JpegExifTest, WrittenFieldsReadBackAndImageStillDecodes) {
  Image8 image(64, 48, 3, 0);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) image.at(x, y, 0) = static_cast<uint8_t>(4 * x);
  const Image8& frozen = image;
  const std::string jpeg = EncodeJpeg(frozen.view());
  ExifFields fields;
  fields.make = "casual3d";
  fields.model = "synthetic partial";
  fields.focal_mm = 4.25;
  fields.focal_plane_px_per_mm = 212.75;
  const std::string with_exif = InsertExif(jpeg, fields);
  // Inserting twice keeps a single EXIF block.
  const std::string twice = InsertExif(with_exif, fields);
  EXPECT_EQ(twice.size(), with_exif.size());

  // One APP1 "Exif" segment right after SOI, little-endian TIFF inside.
  ASSERT_GT(with_exif.size(), jpeg.size());
  EXPECT_EQ(static_cast<uint8_t>(with_exif[2]), 0xFF);
  EXPECT_EQ(static_cast<uint8_t>(with_exif[3]), 0xE1);
  EXPECT_EQ(with_exif.compare(6, 6, std::string("Exif\0\0", 6)), 0);
  EXPECT_EQ(with_exif.compare(12, 4, std::string("II*\0", 4)), 0);
  EXPECT_NE(with_exif.find("synthetic partial"), std::string::npos);
  const Image8 decoded = DecodeImage(with_exif, "with_exif.jpg");
  EXPECT_EQ(decoded.width(), 64);
  EXPECT_EQ(decoded.height(), 48);
  EXPECT_THROW(InsertExif("not a jpeg", fields), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::io
