#include "encoder/level_of_detail.h"

#include <gtest/gtest.h>

#include "format/package_test_scene.h"

namespace casual3d::encoder {
namespace {

TEST(LevelOfDetailTest, HalvingKeepsAValidGraph) {
  const TwoLayerPanorama fine = casual3d::testing::MakePackageTestPanorama(256, 128);
  ASSERT_TRUE(fine.Validate().ok()) << fine.Validate().ToString();
  StatusOr<TwoLayerPanorama> half = HalvePanorama(fine);
  ASSERT_TRUE(half.ok()) << half.status().ToString();
  ASSERT_EQ(half->width(), 128);
  ASSERT_EQ(half->height(), 64);
  EXPECT_TRUE(half->Validate().ok()) << half->Validate().ToString();
  // Point-sampled depth, presence and labels.
  for (int l = 0; l < kNumLayers; ++l) {
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 128; ++x) {
        const size_t c = half->index(x, y), f = fine.index(2 * x, 2 * y);
        ASSERT_EQ(half->layer(l).present[c], fine.layer(l).present[f]);
        ASSERT_EQ(half->layer(l).depth_m[c], fine.layer(l).depth_m[f]);
      }
    }
  }
  // The object's silhouette stays an open depth edge: the front node left of
  // the object (lon < 0, at the equator) does not link right into it.
  int open_edges = 0, links = 0;
  const LayerData& F = half->layer(kFront);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x + 1 < 128; ++x) {
      const size_t a = half->index(x, y), b = half->index(x + 1, y);
      const bool edge = std::fabs(F.depth_m[a] - F.depth_m[b]) > 1.0f;
      const bool linked = GetLink(F.links[a], kRight) == Link::kFront;
      if (edge) open_edges += !linked;
      if (edge && linked) ADD_FAILURE() << "link across a depth edge at " << x << "," << y;
      links += linked;
    }
  EXPECT_GT(open_edges, 10);
  EXPECT_GT(links, 128 * 64 / 2);
  // A second halving works too; an odd size does not.
  StatusOr<TwoLayerPanorama> quarter = HalvePanorama(*half);
  ASSERT_TRUE(quarter.ok());
  EXPECT_TRUE(quarter->Validate().ok());
  EXPECT_EQ(HalvePanorama(TwoLayerPanorama(5, 4)).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace casual3d::encoder
