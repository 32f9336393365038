// The photo import on small generated folders: bad files among good ones,
// mixed formats and orientations, large photos, and devices.

#include "reconstruct/sfm/photo_import.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "reconstruct/io/file_util.h"
#include "reconstruct/io/jpeg_exif.h"

namespace casual3d::sfm {
namespace {

namespace fs = std::filesystem;

class PhotoImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::path(::testing::TempDir()) /
            ("photo_import_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_ / "in");
    fs::create_directories(root_ / "out");
  }
  void TearDown() override { fs::remove_all(root_); }

  // Random colours (each photo distinct), width x height, as JPEG bytes.
  static std::string Jpeg(int seed, int width = 160, int height = 120) {
    cv::Mat img(height, width, CV_8UC3);
    cv::theRNG().state = seed;
    cv::randu(img, 0, 255);
    std::vector<uchar> buf;
    cv::imencode(".jpg", img, buf);
    return std::string(buf.begin(), buf.end());
  }
  void Write(const std::string& name, const std::string& bytes) {
    std::ofstream(root_ / "in" / name, std::ios::binary) << bytes;
  }
  PhotoImport Import(const PhotoImportOptions& options = {}) {
    return ImportPhotos((root_ / "in").string(), (root_ / "out").string(), options, {});
  }
  std::string ErrorOf(const PhotoImportOptions& options = {}) {
    try {
      Import(options);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  }

  fs::path root_;
};

TEST_F(PhotoImportTest, BadAndDuplicateFilesAreSkippedAndListed) {
  for (int i = 0; i < 4; ++i) Write("p" + std::to_string(i) + ".jpg", Jpeg(i + 1));
  const std::string good = Jpeg(9);
  Write("cut.jpg", good.substr(0, good.size() / 2));
  Write("junk.jpg", "not a photo");
  Write("empty.png", "");
  Write("p9_copy.jpg", Jpeg(2));  // Same bytes as p1.jpg.
  const PhotoImport r = Import();
  ASSERT_EQ(r.photos.size(), 4u);
  ASSERT_EQ(r.skipped.size(), 4u);
  std::map<std::string, std::string> reason;
  for (const SkippedPhoto& s : r.skipped) reason[s.file] = s.reason;
  EXPECT_NE(reason["cut.jpg"].find("truncated JPEG"), std::string::npos) << reason["cut.jpg"];
  EXPECT_NE(reason["junk.jpg"].find("not a decodable image"), std::string::npos);
  EXPECT_NE(reason["empty.png"].find("empty file"), std::string::npos);
  EXPECT_EQ(reason["p9_copy.jpg"], "same bytes as p1.jpg");
  for (const auto& p : r.photos) EXPECT_TRUE(fs::exists(root_ / "out" / p.name));
  EXPECT_FALSE(fs::exists(root_ / "out" / "cut.jpg"));

  // Strict: the first bad file stops the import, named; duplicates do not.
  PhotoImportOptions strict;
  strict.skip_unreadable = false;
  const std::string error = ErrorOf(strict);
  EXPECT_NE(error.find("cut.jpg: truncated JPEG"), std::string::npos) << error;
  EXPECT_NE(error.find("--strict-photos"), std::string::npos) << error;
}

TEST_F(PhotoImportTest, TooFewUsablePhotosSaysHowManyAndWhy) {
  Write("a.jpg", Jpeg(1));
  Write("b.jpg", Jpeg(2));
  Write("c.jpg", Jpeg(1));
  Write("d.jpg", "xx");
  const std::string error = ErrorOf();
  EXPECT_NE(error.find("2 usable photos of 4; at least 3 are needed"), std::string::npos) << error;
  EXPECT_NE(error.find("c.jpg: same bytes as a.jpg"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

// Inserts EXIF Orientation `orientation` (and nothing else) into JPEG bytes.
std::string WithOrientation(const std::string& jpeg, int orientation) {
  std::string tiff = std::string("II*\0\x08\0\0\0\x01\0\x12\x01\x03\0\x01\0\0\0", 18);
  tiff += static_cast<char>(orientation);
  tiff += std::string("\0\0\0\0\0\0\0", 7);
  const std::string payload = std::string("Exif\0\0", 6) + tiff;
  std::string app1 = "\xFF\xE1";
  app1 += static_cast<char>((payload.size() + 2) >> 8);
  app1 += static_cast<char>((payload.size() + 2) & 0xFF);
  return jpeg.substr(0, 2) + app1 + payload + jpeg.substr(2);
}

TEST_F(PhotoImportTest, MixedFolderOfFormatsSizesAndOrientations) {
  io::ExifFields phone;
  phone.make = "Phone Co";
  phone.model = "P1";
  phone.focal_mm = 4.0;
  phone.focal_plane_px_per_mm = 40.0;
  Write("a_landscape.jpg", io::InsertExif(Jpeg(1), phone));
  Write("b_landscape.jpg", io::InsertExif(Jpeg(2), phone));
  Write("c_portrait.jpg", WithOrientation(Jpeg(3), 6));  // Stored 160x120, upright 120x160.
  Write("d_other_size.jpg", io::InsertExif(Jpeg(4, 200, 150), phone));  // Same phone, 4:3 smaller.
  cv::Mat grey(90, 120, CV_8UC1);
  cv::randu(grey, 0, 255);
  cv::imwrite((root_ / "in" / "e_grey.png").string(), grey);
  cv::Mat deep(90, 120, CV_16UC3);
  cv::randu(deep, 0, 65535);
  cv::imwrite((root_ / "in" / "f_deep.png").string(), deep);
  cv::imwrite((root_ / "in" / "g_scan.tif").string(), deep);
  const PhotoImport r = Import();
  ASSERT_EQ(r.photos.size(), 7u);
  EXPECT_TRUE(r.skipped.empty());
  std::map<std::string, const ImportedPhoto*> by_source;
  for (const auto& p : r.photos) by_source[p.source] = &p;
  EXPECT_EQ(by_source["c_portrait.jpg"]->width, 120);
  EXPECT_EQ(by_source["c_portrait.jpg"]->height, 160);
  EXPECT_EQ(by_source["g_scan.tif"]->name, "g_scan.tif.jpg");  // Written as JPEG.
  EXPECT_TRUE(fs::exists(root_ / "out" / "g_scan.tif.jpg"));
  // The phone's focal prior: 4 mm * 40 px/mm = 160 px at full size.
  EXPECT_NEAR(by_source["a_landscape.jpg"]->focal_px, 160.0, 0.5);
  EXPECT_NEAR(by_source["d_other_size.jpg"]->focal_px, 160.0, 0.5);
  // One calibration per upright size (and focal): 160x120 phone, 120x160, 200x150, 120x90.
  EXPECT_EQ(r.groups.size(), 4u);
  EXPECT_EQ(by_source["a_landscape.jpg"]->group, by_source["b_landscape.jpg"]->group);
  EXPECT_NE(by_source["a_landscape.jpg"]->group, by_source["c_portrait.jpg"]->group);
}

TEST_F(PhotoImportTest, LargePhotoIsDecodedReducedToTheWorkingSize) {
  cv::Mat big(3000, 4000, CV_8UC3, cv::Scalar(40, 90, 160));
  cv::circle(big, {2000, 1500}, 900, cv::Scalar(200, 10, 10), -1);
  std::vector<uchar> buf;
  cv::imencode(".jpg", big, buf);
  Write("a_big.jpg", std::string(buf.begin(), buf.end()));
  Write("b.jpg", Jpeg(1));
  Write("c.jpg", Jpeg(2));
  PhotoImportOptions options;
  options.working_megapixels = 0.12;
  const PhotoImport r = Import(options);
  const ImportedPhoto& p = r.photos[0];
  ASSERT_EQ(p.source, "a_big.jpg");
  EXPECT_EQ(p.original_width, 4000);
  EXPECT_EQ(p.original_height, 3000);
  EXPECT_EQ(p.width, 400);  // sqrt(0.12e6 * 4 / 3).
  EXPECT_EQ(p.height, 300);
}

TEST_F(PhotoImportTest, DifferentDevicesAreRefusedUnlessAllowed) {
  io::ExifFields a, b;
  a.make = "Maker";
  a.model = "One";
  b.make = "Maker";
  b.model = "Two";
  Write("a.jpg", io::InsertExif(Jpeg(1), a));
  Write("b.jpg", io::InsertExif(Jpeg(2), a));
  Write("c.jpg", io::InsertExif(Jpeg(3), b));
  Write("d.png", "");  // Skipped; the others decide.
  const std::string error = ErrorOf();
  EXPECT_NE(error.find("2 different cameras"), std::string::npos) << error;
  EXPECT_NE(error.find("Maker Two (1 photos, e.g. c.jpg)"), std::string::npos) << error;
  PhotoImportOptions mixed;
  mixed.allow_mixed_devices = true;
  EXPECT_EQ(Import(mixed).groups.size(), 2u);
}

}  // namespace
}  // namespace casual3d::sfm
