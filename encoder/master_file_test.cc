#include "encoder/master_file.h"

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/testing/scratch_dir.h"
#include "format/package_test_scene.h"

namespace casual3d::encoder {
namespace {

namespace fs = std::filesystem;

class MasterFileTest : public casual3d::testing::TestWithScratchDir {};

TEST_F(MasterFileTest, RoundTripIsBitExact) {
  TwoLayerPanorama pano = casual3d::testing::MakePackageTestPanorama(256, 128);
  pano.frame().rotation[0] = 0.0;
  pano.frame().rotation[1] = -1.0;
  pano.frame().rotation[3] = 1.0;
  pano.frame().rotation[4] = 0.0;
  // Values that a lossy or half-float path would change.
  pano.layer(kFront).depth_m[5] = 1.0f + 1e-7f * 3;
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  const std::string path = scratch_.Path("pano.exr");
  Status written = WriteMasterFile(pano, path);
  ASSERT_TRUE(written.ok()) << written.ToString();
  StatusOr<TwoLayerPanorama> read = ReadMasterFile(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_TRUE(*read == pano);
  for (int l = 0; l < kNumLayers; ++l) {
    EXPECT_EQ(0, std::memcmp(read->layer(l).depth_m.data(), pano.layer(l).depth_m.data(),
                             pano.layer(l).depth_m.size() * sizeof(float)));
    EXPECT_EQ(read->layer(l).links, pano.layer(l).links);
  }
  for (int i = 0; i < 9; ++i) EXPECT_EQ(read->frame().rotation[i], pano.frame().rotation[i]);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(read->frame().centre[i], pano.frame().centre[i]);
  // No temporary file is left behind.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) files += entry.is_regular_file();
  EXPECT_EQ(files, 1);
}

TEST_F(MasterFileTest, OddSizeAcrossStripBoundaries) {
  TwoLayerPanorama pano = casual3d::testing::MakePackageTestPanorama(130, 65 + 64);
  ASSERT_TRUE(WriteMasterFile(pano, scratch_.Path("odd.exr")).ok());
  StatusOr<TwoLayerPanorama> read = ReadMasterFile(scratch_.Path("odd.exr"));
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_TRUE(*read == pano);
}

TEST_F(MasterFileTest, RefusesInvalidPanoramaAndLeavesNoFile) {
  TwoLayerPanorama pano = casual3d::testing::MakePackageTestPanorama(64, 32);
  pano.layer(kFront).links[0] = SetLink(0, kRight, Link::kBack);  // Not mutual.
  pano.layer(kBack).present[1] = 0;
  Status s = WriteMasterFile(pano, scratch_.Path("bad.exr"));
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_FALSE(fs::exists(scratch_.Path("bad.exr")));
}

TEST_F(MasterFileTest, MissingFileIsNotFound) {
  StatusOr<TwoLayerPanorama> read = ReadMasterFile(scratch_.Path("nope.exr"));
  EXPECT_EQ(read.status().code(), StatusCode::kNotFound);
  EXPECT_NE(read.status().message().find("nope.exr"), std::string::npos);
}

TEST_F(MasterFileTest, GarbageAndTruncatedFilesAreInvalidData) {
  {
    std::ofstream f(scratch_.Path("garbage.exr"), std::ios::binary);
    f << "this is not an image at all";
  }
  EXPECT_EQ(ReadMasterFile(scratch_.Path("garbage.exr")).status().code(), StatusCode::kInvalidData);

  TwoLayerPanorama pano = casual3d::testing::MakePackageTestPanorama(64, 32);
  ASSERT_TRUE(WriteMasterFile(pano, scratch_.Path("full.exr")).ok());
  std::ifstream in(scratch_.Path("full.exr"), std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);
  for (size_t keep : {size_t{8}, size_t{200}, bytes.size() / 2, bytes.size() - 3}) {
    const std::string cut = scratch_.Path("cut_" + std::to_string(keep) + ".exr");
    std::ofstream out(cut, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(keep));
    out.close();
    StatusOr<TwoLayerPanorama> read = ReadMasterFile(cut);
    EXPECT_FALSE(read.ok()) << "truncated to " << keep << " bytes";
  }
  // Flipped bytes in the pixel data: either refused or a valid panorama, never a crash.
  for (size_t pos = bytes.size() / 3; pos < bytes.size(); pos += bytes.size() / 7) {
    std::vector<char> bad = bytes;
    bad[pos] = static_cast<char>(bad[pos] ^ 0x5A);
    const std::string p = scratch_.Path("flip.exr");
    std::ofstream out(p, std::ios::binary);
    out.write(bad.data(), static_cast<std::streamsize>(bad.size()));
    out.close();
    StatusOr<TwoLayerPanorama> read = ReadMasterFile(p);
    if (read.ok()) {
      EXPECT_TRUE(read->Validate().ok());
    }
  }
}

}  // namespace
}  // namespace casual3d::encoder
