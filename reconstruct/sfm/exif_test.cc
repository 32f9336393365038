#include "reconstruct/sfm/exif.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>

#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/io/jpeg_exif.h"

namespace casual3d::sfm {
namespace {

TEST(ExifTest, ReadsWhatInsertExifWrites) {
  Image8 image(64, 48, 3, 90);
  io::ExifFields fields;
  fields.make = "casual3d";
  fields.model = "synthetic partial";
  fields.focal_mm = 4.25;
  fields.focal_plane_px_per_mm = 212.75;
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("casual3d_exif_" + std::to_string(::getpid()) + ".jpg"))
                               .string();
  const Image8& frozen = image;
  io::WriteFileAtomic(path, io::InsertExif(io::EncodeJpeg(frozen.view()), fields));
  const ExifInfo info = ReadExif(path);
  std::remove(path.c_str());
  EXPECT_TRUE(info.present);
  EXPECT_EQ(info.make, "casual3d");
  EXPECT_EQ(info.model, "synthetic partial");
  EXPECT_NEAR(info.focal_mm, 4.25, 1e-3);
  EXPECT_NEAR(info.focal_plane_px_per_mm, 212.75, 1e-3);
  // A photo downscaled by 2 halves the focal length in pixels.
  EXPECT_NEAR(FocalPixelsFromExif(info, 32, 24, 64), 0.5 * 4.25 * 212.75, 0.01);
}

}  // namespace
}  // namespace casual3d::sfm
