#include "format/two_layer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "format/testing/test_panoramas.h"

namespace casual3d {
namespace {

// A 4x3 panorama with front nodes everywhere, linked to their 4 neighbours.
TwoLayerPanorama FullyLinked(int w = 4, int h = 3) {
  TwoLayerPanorama p(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = p.index(x, y);
      p.layer(kFront).present[i] = 1;
      p.layer(kFront).depth_m[i] = 2.0f;
      p.layer(kFront).normal[3 * i + 2] = 1.0f;
      uint8_t links = 0;
      for (int d = 0; d < kNumDirections; ++d) {
        int nx, ny;
        if (p.Neighbour(x, y, static_cast<Direction>(d), &nx, &ny)) {
          links = SetLink(links, static_cast<Direction>(d), Link::kFront);
        }
      }
      p.layer(kFront).links[i] = links;
    }
  }
  return p;
}

TEST(TwoLayerTest, ConstructorMakesAllNodesAbsentAndValid) {
  TwoLayerPanorama p(8, 4);
  EXPECT_EQ(p.width(), 8);
  EXPECT_EQ(p.height(), 4);
  for (int l = 0; l < kNumLayers; ++l) {
    EXPECT_EQ(p.layer(l).present.size(), 32u);
    EXPECT_EQ(p.layer(l).rgb.size(), 96u);
    EXPECT_EQ(p.layer(l).normal.size(), 96u);
    for (int y = 0; y < 4; ++y) {
      for (int x = 0; x < 8; ++x) EXPECT_FALSE(p.present(l, x, y));
    }
  }
  EXPECT_TRUE(p.Validate().ok()) << p.Validate().ToString();
}

TEST(TwoLayerTest, LinkPackingRoundTrips) {
  uint8_t links = 0;
  links = SetLink(links, kRight, Link::kBack);
  links = SetLink(links, kUp, Link::kFront);
  EXPECT_EQ(links, 0x02 | (0x01 << 6));
  EXPECT_EQ(GetLink(links, kRight), Link::kBack);
  EXPECT_EQ(GetLink(links, kDown), Link::kNone);
  EXPECT_EQ(GetLink(links, kUp), Link::kFront);
  links = SetLink(links, kRight, Link::kNone);
  EXPECT_EQ(links, 0x01 << 6);
  EXPECT_EQ(Opposite(kRight), kLeft);
  EXPECT_EQ(Opposite(kUp), kDown);
}

TEST(TwoLayerTest, NeighbourWrapsColumnsButNotRows) {
  TwoLayerPanorama p(8, 4);
  int nx = -1, ny = -1;
  ASSERT_TRUE(p.Neighbour(7, 2, kRight, &nx, &ny));
  EXPECT_EQ(nx, 0);
  EXPECT_EQ(ny, 2);
  ASSERT_TRUE(p.Neighbour(0, 1, kLeft, &nx, &ny));
  EXPECT_EQ(nx, 7);
  EXPECT_EQ(ny, 1);
  ASSERT_TRUE(p.Neighbour(3, 1, kDown, &nx, &ny));
  EXPECT_EQ(nx, 3);
  EXPECT_EQ(ny, 2);
  ASSERT_TRUE(p.Neighbour(3, 1, kUp, &nx, &ny));
  EXPECT_EQ(ny, 0);
  EXPECT_FALSE(p.Neighbour(3, 0, kUp, &nx, &ny));
  EXPECT_FALSE(p.Neighbour(3, 3, kDown, &nx, &ny));
}

TEST(TwoLayerTest, FullyLinkedGridIsValid) {
  const TwoLayerPanorama p = FullyLinked();
  EXPECT_TRUE(p.Validate().ok()) << p.Validate().ToString();
}

TEST(TwoLayerTest, ProceduralRoomIsValidAndHasBothLayers) {
  const TwoLayerPanorama p = testing::MakeRoomPanorama(128, 64);
  ASSERT_TRUE(p.Validate().ok()) << p.Validate().ToString();
  int back = 0, cross = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 128; ++x) {
      back += p.present(kBack, x, y);
      const uint8_t links = p.layer(kFront).links[p.index(x, y)];
      for (int d = 0; d < kNumDirections; ++d) {
        cross += GetLink(links, static_cast<Direction>(d)) == Link::kBack;
      }
    }
  }
  EXPECT_GT(back, 100);  // The disocclusion behind the sphere.
  EXPECT_GT(cross, 0);   // Front room nodes link to back room nodes around it.
}

TEST(TwoLayerTest, RejectsWrongArraySize) {
  TwoLayerPanorama p = FullyLinked();
  p.layer(kBack).normal.resize(5);
  const Status s = p.Validate();
  EXPECT_EQ(s.code(), StatusCode::kInvalidData);
  EXPECT_EQ(s.message(), "back layer: normal has 5 elements, expected 36");
}

TEST(TwoLayerTest, RejectsOversizedAndEmpty) {
  EXPECT_EQ(TwoLayerPanorama(32769, 1).Validate().code(), StatusCode::kLimitExceeded);
  const Status tall = TwoLayerPanorama(2, 16385).Validate();
  EXPECT_EQ(tall.code(), StatusCode::kLimitExceeded);
  EXPECT_EQ(tall.message(), "panorama size 2x16385 exceeds the limit of 32768x16384");
  EXPECT_TRUE(TwoLayerPanorama(1, 1).Validate().ok());
  EXPECT_EQ(TwoLayerPanorama().Validate().code(), StatusCode::kInvalidData);
}

TEST(TwoLayerTest, RejectsBadDepth) {
  for (float bad : {0.0f, -1.0f, std::numeric_limits<float>::infinity(),
                    std::numeric_limits<float>::quiet_NaN()}) {
    TwoLayerPanorama p = FullyLinked();
    p.layer(kFront).depth_m[p.index(2, 1)] = bad;
    const Status s = p.Validate();
    EXPECT_EQ(s.code(), StatusCode::kInvalidData);
    EXPECT_NE(s.message().find("front node (2, 1): depth"), std::string::npos) << s.message();
  }
}

TEST(TwoLayerTest, NormalsMustBeUnitOrZero) {
  TwoLayerPanorama p = FullyLinked();
  const size_t i = 3 * p.index(1, 1);
  p.layer(kFront).normal[i + 2] = 0.0f;  // Zero: unlit, allowed.
  EXPECT_TRUE(p.Validate().ok());
  p.layer(kFront).normal[i] = 0.6f;
  p.layer(kFront).normal[i + 1] = 0.8f;
  EXPECT_TRUE(p.Validate().ok());
  p.layer(kFront).normal[i + 1] = 0.81f;  // Length 1.006.
  EXPECT_NE(p.Validate().message().find("normal has length"), std::string::npos);
  p.layer(kFront).normal[i + 1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(p.Validate().message().find("normal is not finite"), std::string::npos);
}

TEST(TwoLayerTest, RejectsBadLabelAndPresentFlag) {
  TwoLayerPanorama p = FullyLinked();
  p.layer(kFront).label[p.index(0, 0)] = 1;
  EXPECT_TRUE(p.Validate().ok());
  p.layer(kFront).label[p.index(0, 0)] = 2;
  EXPECT_NE(p.Validate().message().find("label 2"), std::string::npos);
  p = FullyLinked();
  p.layer(kFront).present[p.index(0, 0)] = 7;
  EXPECT_NE(p.Validate().message().find("present flag 7"), std::string::npos);
}

TEST(TwoLayerTest, AbsentNodesMustBeAllZero) {
  TwoLayerPanorama p = FullyLinked();
  p.layer(kBack).rgb[3 * p.index(3, 2) + 1] = 9;
  EXPECT_EQ(p.Validate().message(), "back node (3, 2): absent node has non-zero fields");
  p = FullyLinked();
  p.layer(kBack).depth_m[p.index(3, 2)] = 1.0f;
  EXPECT_FALSE(p.Validate().ok());
  p = FullyLinked();
  p.layer(kBack).links[p.index(3, 2)] = 1;
  EXPECT_FALSE(p.Validate().ok());
}

TEST(TwoLayerTest, LinksMustBeMutual) {
  TwoLayerPanorama p = FullyLinked();
  uint8_t& links = p.layer(kFront).links[p.index(3, 1)];
  links = SetLink(links, kLeft, Link::kNone);  // (2,1) still links right to (3,1).
  const Status s = p.Validate();
  EXPECT_EQ(s.message(), "front node (2, 1): right link to front node (3, 1) is not mutual");
}

TEST(TwoLayerTest, LinksMustPointAtPresentNodes) {
  TwoLayerPanorama p = FullyLinked();
  uint8_t& links = p.layer(kFront).links[p.index(1, 1)];
  links = SetLink(links, kDown, Link::kBack);
  EXPECT_EQ(p.Validate().message(),
            "front node (1, 1): down link points at back node (1, 2), which is absent");
  links = SetLink(links, kDown, static_cast<Link>(3));
  EXPECT_NE(p.Validate().message().find("reserved value 3"), std::string::npos);
}

TEST(TwoLayerTest, LinksDoNotWrapRows) {
  TwoLayerPanorama p = FullyLinked();
  uint8_t& links = p.layer(kFront).links[p.index(2, 0)];
  links = SetLink(links, kUp, Link::kFront);
  EXPECT_NE(p.Validate().message().find("up link points outside the panorama"), std::string::npos);
}

TEST(TwoLayerTest, SeamLinksAreChecked) {
  TwoLayerPanorama p = FullyLinked();
  uint8_t& links = p.layer(kFront).links[p.index(0, 2)];
  links = SetLink(links, kLeft, Link::kNone);
  EXPECT_EQ(p.Validate().message(),
            "front node (3, 2): right link to front node (0, 2) is not mutual");
}

TEST(TwoLayerTest, CrossLayerLinksAreValidWhenMutual) {
  TwoLayerPanorama p = FullyLinked();
  // Give (2,1) a back node linked to the front node (1,1) on its left.
  const size_t i = p.index(2, 1);
  p.layer(kBack).present[i] = 1;
  p.layer(kBack).depth_m[i] = 5.0f;
  p.layer(kBack).label[i] = 1;
  p.layer(kBack).links[i] = SetLink(0, kLeft, Link::kFront);
  uint8_t& l11 = p.layer(kFront).links[p.index(1, 1)];
  l11 = SetLink(l11, kRight, Link::kBack);
  uint8_t& l21 = p.layer(kFront).links[i];
  l21 = SetLink(l21, kLeft, Link::kNone);
  EXPECT_TRUE(p.Validate().ok()) << p.Validate().ToString();
}

TEST(TwoLayerTest, FrameMustBeARotation) {
  TwoLayerPanorama p = FullyLinked();
  p.frame().rotation[0] = -1.0;  // A reflection.
  EXPECT_NE(p.Validate().message().find("reflection"), std::string::npos);
  p.frame().rotation[0] = 2.0;
  EXPECT_NE(p.Validate().message().find("not orthonormal"), std::string::npos);
  p.frame().rotation[0] = 1.0;
  p.frame().centre[1] = std::numeric_limits<double>::infinity();
  EXPECT_NE(p.Validate().message().find("centre is not finite"), std::string::npos);
}

TEST(TwoLayerTest, EqualityComparesEveryField) {
  const TwoLayerPanorama a = FullyLinked();
  TwoLayerPanorama b = FullyLinked();
  EXPECT_TRUE(a == b);
  b.layer(kFront).rgb[5] = 1;
  EXPECT_FALSE(a == b);
  b = FullyLinked();
  b.layer(kFront).depth_m[3] = 2.5f;
  EXPECT_FALSE(a == b);
  b = FullyLinked();
  b.frame().centre[2] = 0.1;
  EXPECT_FALSE(a == b);
  b = FullyLinked();
  b.layer(kBack).label[0] = 1;
  EXPECT_FALSE(a == b);
  EXPECT_FALSE(a == FullyLinked(4, 4));
}

}  // namespace
}  // namespace casual3d
