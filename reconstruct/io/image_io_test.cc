#include "reconstruct/io/image_io.h"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include <cstdio>
#include <jpeglib.h>
#include <opencv2/imgproc.hpp>

#include "base/testing/scratch_dir.h"
#include "reconstruct/io/cv_bridge.h"

namespace casual3d::io {
namespace {

namespace fs = std::filesystem;

class ImageIoTest : public casual3d::testing::TestWithScratchDir {};

// A smooth colour ramp with a distinct value in each channel, 40x30.
Image8 Ramp(int w = 40, int h = 30) {
  Image8 img(w, h, 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      img.at(x, y, 0) = static_cast<uint8_t>(x * 255 / (w - 1));
      img.at(x, y, 1) = static_cast<uint8_t>(y * 255 / (h - 1));
      img.at(x, y, 2) = static_cast<uint8_t>(128 + 60 * std::sin(0.2 * (x + y)));
    }
  }
  return img;
}

TEST_F(ImageIoTest, PngRoundTripIsExactAndKeepsRgbOrder) {
  const Image8 img = Ramp();
  WritePng(scratch_.Path("a.png"), img.view());
  const Image8 back = ReadImage(scratch_.Path("a.png"));
  EXPECT_EQ(back, img);
  // Red grows with x: a BGR/RGB swap would put the ramp in channel 2.
  EXPECT_EQ(back.at(39, 0, 0), 255);
  EXPECT_EQ(back.at(0, 0, 0), 0);
}

TEST_F(ImageIoTest, GreyPngIsExpandedToRgb) {
  Image8 grey(8, 4, 1);
  for (int i = 0; i < 32; ++i) grey.data()[i] = static_cast<uint8_t>(i * 8);
  WritePng(scratch_.Path("g.png"), grey);
  const Image8 back = ReadImage(scratch_.Path("g.png"));
  ASSERT_EQ(back.channels(), 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(back.at(x, y, c), grey.at(x, y));
}

TEST_F(ImageIoTest, JpegRoundTripIsCloseAndQualityMatters) {
  const Image8 img = Ramp(64, 48);
  WriteJpeg(scratch_.Path("hi.jpg"), img, {95});
  WriteJpeg(scratch_.Path("lo.jpg"), img, {30});
  const Image8 back = ReadImage(scratch_.Path("hi.jpg"));
  ASSERT_EQ(back.width(), 64);
  ASSERT_EQ(back.height(), 48);
  double sum = 0;
  for (size_t i = 0; i < img.size(); ++i) sum += std::abs(back.data()[i] - img.data()[i]);
  EXPECT_LT(sum / img.size(), 2.0);
  EXPECT_LT(fs::file_size(scratch_.Path("lo.jpg")), fs::file_size(scratch_.Path("hi.jpg")));
  // Same pixels and quality give the same bytes.
  WriteJpeg(scratch_.Path("hi2.jpg"), img, {95});
  EXPECT_EQ(ReadFile(scratch_.Path("hi.jpg")), ReadFile(scratch_.Path("hi2.jpg")));
}

TEST_F(ImageIoTest, JpegQualityIsChecked) {
  const Image8 img = Ramp();
  EXPECT_THROW(WriteJpeg(scratch_.Path("q.jpg"), img, {0}), IoException);
  EXPECT_THROW(WriteJpeg(scratch_.Path("q.jpg"), img, {101}), IoException);
  EXPECT_FALSE(fs::exists(scratch_.Path("q.jpg")));
}

TEST_F(ImageIoTest, GarbageIsNotADecodableImage) {
  WriteFileAtomic(scratch_.Path("junk.jpg"), "this is not an image at all");
  try {
    ReadImage(scratch_.Path("junk.jpg"));
    FAIL() << "expected IoException";
  } catch (const IoException& e) {
    EXPECT_EQ(std::string(e.what()), scratch_.Path("junk.jpg") + ": not a decodable image");
  }
  WriteFileAtomic(scratch_.Path("empty.png"), "");
  EXPECT_THROW(ReadImage(scratch_.Path("empty.png")), IoException);
}

TEST_F(ImageIoTest, MissingFileNamesThePath) {
  try {
    ReadImage(scratch_.Path("nope.jpg"));
    FAIL() << "expected IoException";
  } catch (const IoException& e) {
    EXPECT_NE(std::string(e.what()).find(scratch_.Path("nope.jpg") + ": cannot open"), std::string::npos)
        << e.what();
  }
}

TEST_F(ImageIoTest, FailedWriteLeavesNothingBehind) {
  const Image8 img = Ramp();
  EXPECT_THROW(WritePng(scratch_.Path("no_such_dir/a.png"), img.view()), IoException);
  EXPECT_THROW(WritePng(scratch_.Path("two.png"), Image8(4, 4, 2)), IoException);
  EXPECT_TRUE(fs::is_empty(dir_));
}

// Inserts an EXIF APP1 segment with Orientation = `orientation` after the SOI marker.
std::string WithExifOrientation(const std::string& jpeg, int orientation) {
  std::string tiff = std::string("II*\0", 4) + std::string("\x08\0\0\0", 4);  // Header, IFD0 at 8.
  tiff += std::string("\x01\0", 2);                       // One entry.
  tiff += std::string("\x12\x01\x03\0\x01\0\0\0", 8);     // Tag 0x0112, SHORT, count 1.
  tiff += static_cast<char>(orientation);
  tiff += std::string("\0\0\0", 3);                       // Value (padded to 4 bytes).
  tiff += std::string("\0\0\0\0", 4);                     // No next IFD.
  const std::string payload = std::string("Exif\0\0", 6) + tiff;
  const size_t len = payload.size() + 2;
  std::string app1 = "\xFF\xE1";
  app1 += static_cast<char>(len >> 8);
  app1 += static_cast<char>(len & 0xFF);
  app1 += payload;
  return jpeg.substr(0, 2) + app1 + jpeg.substr(2);
}

TEST_F(ImageIoTest, ExifOrientationIsAppliedOnlyWhenAsked) {
  const Image8 img = Ramp(64, 32);
  const std::string jpeg = EncodeJpeg(img.view(), {95});
  WriteFileAtomic(scratch_.Path("rot.jpg"), WithExifOrientation(jpeg, 6));  // 6: rotate 90 clockwise.
  const Image8 stored = ReadImage(scratch_.Path("rot.jpg"));
  EXPECT_EQ(stored.width(), 64);
  EXPECT_EQ(stored.height(), 32);
  ReadImageOptions options;
  options.apply_exif_orientation = true;
  const Image8 upright = ReadImage(scratch_.Path("rot.jpg"), options);
  EXPECT_EQ(upright.width(), 32);
  EXPECT_EQ(upright.height(), 64);
}

TEST_F(ImageIoTest, MaxSideIsEnforced) {
  WritePng(scratch_.Path("big.png"), Ramp(40, 30));
  ReadImageOptions options;
  options.max_side = 32;
  EXPECT_THROW(ReadImage(scratch_.Path("big.png"), options), IoException);
}

TEST_F(ImageIoTest, TruncatedJpegIsRefusedAndCompleteOnesPass) {
  const Image8 ramp = Ramp(64, 48);
  const std::string jpeg = EncodeJpeg(std::as_const(ramp).view(), {90});
  EXPECT_TRUE(JpegIsComplete(jpeg));
  int w = 0, h = 0;
  ASSERT_TRUE(JpegSize(jpeg, &w, &h));
  EXPECT_EQ(w, 64);
  EXPECT_EQ(h, 48);
  // libjpeg alone decodes a cut file with grey where the data is missing.
  WriteFileAtomic(scratch_.Path("cut.jpg"), jpeg.substr(0, jpeg.size() * 2 / 3));
  EXPECT_FALSE(JpegIsComplete(ReadFile(scratch_.Path("cut.jpg"))));
  try {
    ReadImage(scratch_.Path("cut.jpg"));
    FAIL() << "expected IoException";
  } catch (const IoException& e) {
    EXPECT_NE(std::string(e.what()).find(scratch_.Path("cut.jpg") + ": truncated JPEG"), std::string::npos)
        << e.what();
  }
  // Bytes after the end-of-image marker (phone trailers) are fine.
  EXPECT_TRUE(JpegIsComplete(jpeg + "trailer"));
  EXPECT_FALSE(JpegIsComplete("not a jpeg"));
}

TEST_F(ImageIoTest, LargeJpegIsDecodedDownscaled) {
  const Image8 img = Ramp(800, 600);
  WriteFileAtomic(scratch_.Path("big.jpg"), WithExifOrientation(EncodeJpeg(std::as_const(img).view(), {90}), 6));
  ReadImageOptions options;
  options.apply_exif_orientation = true;
  options.min_decoded_pixels = 100 * 75;  // 800x600 / 8 per side still has that many.
  DecodedImageInfo info;
  const Image8 small = ReadImage(scratch_.Path("big.jpg"), options, &info);
  EXPECT_EQ(info.reduction, 8);
  EXPECT_EQ(small.width(), 75);  // Turned upright by the orientation.
  EXPECT_EQ(small.height(), 100);
  EXPECT_EQ(info.full_width, 600);
  EXPECT_EQ(info.full_height, 800);
  options.min_decoded_pixels = 300 * 220;  // Only halving keeps that many.
  EXPECT_EQ(ReadImage(scratch_.Path("big.jpg"), options, &info).width(), 300);
  EXPECT_EQ(info.reduction, 2);
}

TEST_F(ImageIoTest, SixteenBitPngAndTiffAreRead) {
  cv::Mat deep(30, 40, CV_16UC3);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) deep.at<cv::Vec3w>(y, x) = cv::Vec3w(0, y * 2000, x * 1600);
  ASSERT_TRUE(cv::imwrite(scratch_.Path("deep.png"), deep));
  ASSERT_TRUE(cv::imwrite(scratch_.Path("deep.tif"), deep));
  for (const char* name : {"deep.png", "deep.tif"}) {
    DecodedImageInfo info;
    const Image8 back = ReadImage(scratch_.Path(name), {}, &info);
    ASSERT_EQ(back.width(), 40) << name;
    // Scaled from 16 to 8 bits: 39 * 1600 / 257 = 242.8 in red (OpenCV's BGR blue).
    EXPECT_NEAR(back.at(39, 0, 0), 243, 1) << name;
    EXPECT_NEAR(back.at(0, 29, 1), 29 * 2000 / 257.0, 1) << name;
    EXPECT_EQ(info.format, std::string(name).find("png") != std::string::npos ? "png" : "tiff");
  }
}

TEST_F(ImageIoTest, CmykJpegIsConvertedToRgb) {
  // A CMYK JPEG as Adobe applications write it (inverted CMYK, Adobe APP14).
  const int w = 32, h = 16;
  std::vector<uint8_t> cmyk(w * h * 4);
  for (int i = 0; i < w * h; ++i) {
    // Pure red: no cyan, full magenta and yellow, no black; stored inverted.
    cmyk[i * 4 + 0] = 255, cmyk[i * 4 + 1] = 0, cmyk[i * 4 + 2] = 0, cmyk[i * 4 + 3] = 255;
  }
  jpeg_compress_struct cinfo;
  jpeg_error_mgr jerr;
  cinfo.err = jpeg_std_error(&jerr);
  jpeg_create_compress(&cinfo);
  unsigned char* out = nullptr;
  unsigned long out_size = 0;
  jpeg_mem_dest(&cinfo, &out, &out_size);
  cinfo.image_width = w;
  cinfo.image_height = h;
  cinfo.input_components = 4;
  cinfo.in_color_space = JCS_CMYK;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, 95, TRUE);
  jpeg_start_compress(&cinfo, TRUE);
  for (int y = 0; y < h; ++y) {
    JSAMPROW row = cmyk.data() + y * w * 4;
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  const std::string bytes(reinterpret_cast<char*>(out), out_size);
  jpeg_destroy_compress(&cinfo);
  std::free(out);
  const Image8 back = DecodeImage(bytes, "cmyk.jpg");
  ASSERT_EQ(back.channels(), 3);
  EXPECT_GT(back.at(5, 5, 0), 200);
  EXPECT_LT(back.at(5, 5, 1), 60);
  EXPECT_LT(back.at(5, 5, 2), 60);
}

TEST(CvBridgeTest, MatAndViewShareMemory) {
  Image8 img(10, 6, 3, 7);
  cv::Mat mat = ToMat(img);
  EXPECT_EQ(mat.data, img.data());
  EXPECT_EQ(mat.cols, 10);
  EXPECT_EQ(mat.rows, 6);
  EXPECT_EQ(mat.type(), CV_8UC3);
  mat.at<cv::Vec3b>(2, 4)[1] = 200;  // Row 2, column 4, channel 1.
  EXPECT_EQ(img.at(4, 2, 1), 200);

  // A cropped view keeps the parent's stride.
  ImageView<uint8_t> crop = img.view().Crop(3, 1, 4, 2);
  cv::Mat crop_mat = ToMat(crop);
  EXPECT_EQ(crop_mat.step[0], 30u);
  EXPECT_EQ(crop_mat.at<cv::Vec3b>(1, 1)[1], 200);

  cv::Mat f(5, 7, CV_32FC2, cv::Scalar(1.5f, -2.0f));
  ImageView<float> v = ToView<float>(f(cv::Rect(2, 1, 3, 3)));
  EXPECT_EQ(v.width(), 3);
  EXPECT_EQ(v.stride(), 14);
  EXPECT_FLOAT_EQ(v.at(0, 0, 1), -2.0f);
  v.at(0, 0, 0) = 9.0f;
  EXPECT_FLOAT_EQ(f.at<cv::Vec2f>(1, 2)[0], 9.0f);
}

}  // namespace
}  // namespace casual3d::io
