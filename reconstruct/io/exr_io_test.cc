#include "reconstruct/io/exr_io.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <utility>

#include <gtest/gtest.h>

#include "base/testing/scratch_dir.h"
namespace casual3d::io {
namespace {

namespace fs = std::filesystem;

class ExrIoTest : public casual3d::testing::TestWithScratchDir {};

ImageF Pattern(int w, int h, int c) {
  ImageF img(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) img.at(x, y, k) = 0.001f * x - 0.37f * y + 100.0f * k + 1e-7f;
  return img;
}

TEST_F(ExrIoTest, MultiChannelRoundTripIsExact) {
  ImageF img = Pattern(37, 19, 3);
  img.at(3, 4, 2) = std::numeric_limits<float>::infinity();
  img.at(5, 6, 1) = std::numeric_limits<float>::quiet_NaN();
  const std::vector<std::string> names = {"front.Z", "back.Z", "A"};
  WriteExr(scratch_.Path("m.exr"), img, names);

  // The file keeps channels sorted by name.
  EXPECT_EQ(ReadExrChannelNames(scratch_.Path("m.exr")),
            (std::vector<std::string>{"A", "back.Z", "front.Z"}));

  const ImageF back = ReadExrChannels(scratch_.Path("m.exr"), names);
  ASSERT_EQ(back.width(), 37);
  ASSERT_EQ(back.height(), 19);
  ASSERT_EQ(back.channels(), 3);
  for (size_t i = 0; i < img.size(); ++i) {
    if (std::isnan(img.data()[i])) {
      EXPECT_TRUE(std::isnan(back.data()[i]));
    } else {
      EXPECT_EQ(back.data()[i], img.data()[i]) << i;
    }
  }
  const ExrImage all = ReadExr(scratch_.Path("m.exr"));
  ASSERT_EQ(all.channels.size(), 3u);
  EXPECT_EQ(all.channels[0], "A");
  EXPECT_EQ(all.pixels.at(7, 8, 0), img.at(7, 8, 2));
  EXPECT_EQ(all.pixels.at(7, 8, 2), img.at(7, 8, 0));
}

TEST_F(ExrIoTest, SingleChannelFromStridedViewAndCompressions) {
  ImageF big = Pattern(50, 40, 1);
  ImageView<const float> crop = std::as_const(big).view().Crop(10, 5, 20, 15);
  for (ExrCompression c : {ExrCompression::kNone, ExrCompression::kZip, ExrCompression::kPiz}) {
    ExrWriteOptions options;
    options.compression = c;
    WriteExr(scratch_.Path("z.exr"), crop, {"Z"}, options);
    const ImageF z = ReadExrChannels(scratch_.Path("z.exr"), {"Z"});
    ASSERT_EQ(z.width(), 20);
    ASSERT_EQ(z.height(), 15);
    EXPECT_EQ(z.at(0, 0), big.at(10, 5));
    EXPECT_EQ(z.at(19, 14), big.at(29, 19));
  }
}

TEST_F(ExrIoTest, HalfIsApproximate) {
  const ImageF img = Pattern(16, 8, 1);
  ExrWriteOptions options;
  options.pixel_type = ExrPixelType::kHalf;
  WriteExr(scratch_.Path("h.exr"), img, {"Y"}, options);
  const ImageF back = ReadExrChannels(scratch_.Path("h.exr"), {"Y"});
  for (size_t i = 0; i < img.size(); ++i) {
    EXPECT_NEAR(back.data()[i], img.data()[i], 1e-3 * (1 + std::abs(img.data()[i])));
  }
}

TEST_F(ExrIoTest, ErrorsNameTheFileAndLeaveNothingBehind) {
  const ImageF img = Pattern(4, 4, 2);
  EXPECT_THROW(WriteExr(scratch_.Path("a.exr"), img, {"Z"}), IoException);       // Count mismatch.
  EXPECT_THROW(WriteExr(scratch_.Path("a.exr"), img, {"Z", "Z"}), IoException);  // Repeated.
  EXPECT_THROW(WriteExr(scratch_.Path("nodir/a.exr"), img, {"X", "Y"}), IoException);
  EXPECT_TRUE(fs::is_empty(dir_));

  WriteExr(scratch_.Path("b.exr"), img, {"X", "Y"});
  try {
    ReadExrChannels(scratch_.Path("b.exr"), {"X", "Z"});
    FAIL() << "expected IoException";
  } catch (const IoException& e) {
    EXPECT_EQ(std::string(e.what()), scratch_.Path("b.exr") + ": OpenEXR channel 'Z' is missing");
  }
  WriteFileAtomic(scratch_.Path("junk.exr"), "not an exr file");
  EXPECT_THROW(ReadExr(scratch_.Path("junk.exr")), IoException);
  EXPECT_THROW(ReadExr(scratch_.Path("missing.exr")), IoException);
  // A truncated file is refused, not crashed on.
  const std::string bytes = ReadFile(scratch_.Path("b.exr"));
  WriteFileAtomic(scratch_.Path("cut.exr"), bytes.substr(0, bytes.size() / 2));
  EXPECT_THROW(ReadExr(scratch_.Path("cut.exr")), IoException);
}

}  // namespace
}  // namespace casual3d::io
