#include "encoder/package_fit.h"

#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "format/package_test_scene.h"

namespace casual3d::encoder {
namespace {

class PackageFitTest : public ::testing::Test {
 protected:
  void SetUp() override {
    pano_ = casual3d::testing::MakePackageTestPanorama(512, 256);
    options_ = DeliveryPackageOptions();
    options_.tile_size = 128;
    options_.levels = 3;
    options_.num_threads = 2;
  }
  uint64_t SizeWith(const PackageOptions& options) {
    PackageStats stats;
    EXPECT_TRUE(EncodePackage(pano_, options, &stats).ok());
    return stats.total_bytes;
  }
  TwoLayerPanorama pano_;
  PackageOptions options_;
};

TEST_F(PackageFitTest, NoBudgetOrRoomKeepsTheGivenSettings) {
  const uint64_t size = SizeWith(options_);
  for (uint64_t budget : {uint64_t{0}, size}) {
    PackageFitOptions fit;
    fit.max_bytes = budget;
    StatusOr<PackageFit> r = EncodePackageWithin(pano_, options_, fit);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->stats.total_bytes, size);
    EXPECT_EQ(r->encodings, 1);
    EXPECT_FALSE(r->options.lossy_normals);
    EXPECT_EQ(r->options.color_quality, options_.color_quality);
  }
}

TEST_F(PackageFitTest, LowersColourQualityToTheHighestThatFits) {
  PackageOptions at80 = options_;
  at80.color_quality = 80;
  const uint64_t budget = SizeWith(at80);
  PackageFitOptions fit;
  fit.max_bytes = budget;
  fit.allow_lossy_normals = false;
  StatusOr<PackageFit> r = EncodePackageWithin(pano_, options_, fit);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_LE(r->stats.total_bytes, budget);
  EXPECT_GE(r->options.color_quality, 80.0f);
  EXPECT_LT(r->options.color_quality, 90.0f);
  EXPECT_FALSE(r->options.lossy_normals);
  // One step higher does not fit.
  PackageOptions above = r->options;
  above.color_quality += 1;
  EXPECT_GT(SizeWith(above), budget);
  // Only the colour tiles differ from a fresh encoding at that quality.
  PackageStats fresh;
  StatusOr<PackageFiles> again = EncodePackage(pano_, r->options, &fresh);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(*again, r->files);
  EXPECT_EQ(fresh.total_bytes, r->stats.total_bytes);
}

TEST_F(PackageFitTest, TriesLossyNormalsBeforeColour) {
  PackageOptions lossy = options_;
  lossy.lossy_normals = true;
  const uint64_t lossy_size = SizeWith(lossy);
  const uint64_t size = SizeWith(options_);
  if (lossy_size >= size) GTEST_SKIP() << "lossy normals are not smaller on this panorama";
  PackageFitOptions fit;
  fit.max_bytes = lossy_size;
  StatusOr<PackageFit> r = EncodePackageWithin(pano_, options_, fit);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_TRUE(r->options.lossy_normals);
  EXPECT_EQ(r->options.color_quality, options_.color_quality);
  EXPECT_EQ(r->encodings, 2);
}

TEST_F(PackageFitTest, RefusesWithOneMessage) {
  // What nothing fits in names the smallest package reached; a bad floor is
  // named too.
  const std::pair<float, const char*> cases[] = {
      {85.0f, "does not fit in 1.0 KB: the smallest was"},
      {85.0f, "colour quality 85"},
      {120.0f, "min_color_quality 120"},
  };
  for (const auto& [floor, message] : cases) {
    PackageFitOptions fit;
    fit.max_bytes = 1000;
    fit.min_color_quality = floor;
    StatusOr<PackageFit> r = EncodePackageWithin(pano_, options_, fit);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(r.status().message().find(message), std::string::npos) << r.status().message();
  }
}

}  // namespace
}  // namespace casual3d::encoder
