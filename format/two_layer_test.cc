#include "format/two_layer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "format/testing/test_panoramas.h"

namespace casual3d {

// Runs Validate's two scans separately.
struct TwoLayerPanoramaTestAccess {
  static bool FastScanAccepts(const TwoLayerPanorama& p, int threads = 1) {
    return p.ScanIsValid<true>(threads);
  }
  static Status NodeByNodeScan(const TwoLayerPanorama& p) { return p.FirstNodeOrLinkProblem(); }
};

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

TEST(TwoLayerTest, NodeDepthRangeSpansThePresentNodesOfBothLayers) {
  TwoLayerPanorama pano(8, 4);
  double near_m = -1, far_m = -1;
  EXPECT_FALSE(pano.NodeDepthRange(&near_m, &far_m));
  EXPECT_EQ(near_m, -1);
  EXPECT_EQ(far_m, -1);
  LayerData& f = pano.layer(kFront);
  LayerData& b = pano.layer(kBack);
  f.present[pano.index(1, 1)] = 1;
  f.depth_m[pano.index(1, 1)] = 2.5f;
  f.present[pano.index(2, 1)] = 1;
  f.depth_m[pano.index(2, 1)] = 4.0f;
  b.present[pano.index(2, 1)] = 1;
  b.depth_m[pano.index(2, 1)] = 30.0f;
  f.depth_m[pano.index(5, 2)] = 0.1f;  // Absent: not counted.
  ASSERT_TRUE(pano.NodeDepthRange(&near_m, &far_m));
  EXPECT_EQ(near_m, 2.5);
  EXPECT_EQ(far_m, 30.0);
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

// One corruption of each kind of field, in either layer, and the exact first
// message it must give.
TEST(TwoLayerTest, EachKindOfCorruptionGivesItsMessage) {
  // The fully linked front grid plus a back node at (2, 1) linked left to the
  // front node (1, 1) (as in CrossLayerLinksAreValidWhenMutual).
  const auto base = [] {
    TwoLayerPanorama p = FullyLinked();
    const size_t i = p.index(2, 1);
    p.layer(kBack).present[i] = 1;
    p.layer(kBack).depth_m[i] = 5.0f;
    p.layer(kBack).normal[3 * i + 1] = 1.0f;
    p.layer(kBack).label[i] = 1;
    p.layer(kBack).links[i] = SetLink(0, kLeft, Link::kFront);
    uint8_t& l11 = p.layer(kFront).links[p.index(1, 1)];
    l11 = SetLink(l11, kRight, Link::kBack);
    uint8_t& l21 = p.layer(kFront).links[i];
    l21 = SetLink(l21, kLeft, Link::kNone);
    return p;
  };
  ASSERT_TRUE(base().Validate().ok()) << base().Validate().ToString();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  struct Case {
    const char* what;
    std::function<void(TwoLayerPanorama&)> corrupt;
    const char* message;
  };
  const auto at = [](TwoLayerPanorama& p, int x, int y) { return p.index(x, y); };
  const std::vector<Case> cases = {
      {"present flag", [&](TwoLayerPanorama& p) { p.layer(kBack).present[at(p, 2, 1)] = 2; },
       "back node (2, 1): present flag 2 is not 0 or 1"},
      {"absent rgb", [&](TwoLayerPanorama& p) { p.layer(kBack).rgb[3 * at(p, 0, 2) + 2] = 1; },
       "back node (0, 2): absent node has non-zero fields"},
      {"absent depth", [&](TwoLayerPanorama& p) { p.layer(kBack).depth_m[at(p, 3, 0)] = nan; },
       "back node (3, 0): absent node has non-zero fields"},
      {"absent normal",
       [&](TwoLayerPanorama& p) { p.layer(kBack).normal[3 * at(p, 1, 1)] = -1.0f; },
       "back node (1, 1): absent node has non-zero fields"},
      {"absent label", [&](TwoLayerPanorama& p) { p.layer(kBack).label[at(p, 1, 0)] = 1; },
       "back node (1, 0): absent node has non-zero fields"},
      {"absent links", [&](TwoLayerPanorama& p) { p.layer(kBack).links[at(p, 3, 2)] = 0x40; },
       "back node (3, 2): absent node has non-zero fields"},
      {"negative depth", [&](TwoLayerPanorama& p) { p.layer(kFront).depth_m[at(p, 3, 1)] = -2.0f; },
       "front node (3, 1): depth -2.000000 m is not finite and positive"},
      {"zero depth", [&](TwoLayerPanorama& p) { p.layer(kBack).depth_m[at(p, 2, 1)] = 0.0f; },
       "back node (2, 1): depth 0.000000 m is not finite and positive"},
      {"infinite depth", [&](TwoLayerPanorama& p) { p.layer(kFront).depth_m[at(p, 0, 0)] = inf; },
       "front node (0, 0): depth inf m is not finite and positive"},
      {"infinite normal",
       [&](TwoLayerPanorama& p) { p.layer(kFront).normal[3 * at(p, 2, 2)] = -inf; },
       "front node (2, 2): normal is not finite"},
      {"NaN normal", [&](TwoLayerPanorama& p) { p.layer(kBack).normal[3 * at(p, 2, 1) + 2] = nan; },
       "back node (2, 1): normal is not finite"},
      {"short normal",
       [&](TwoLayerPanorama& p) { p.layer(kFront).normal[3 * at(p, 1, 2) + 2] = 0.99f; },
       "front node (1, 2): normal has length 0.990000, expected 1 or 0"},
      {"long normal",
       [&](TwoLayerPanorama& p) { p.layer(kBack).normal[3 * at(p, 2, 1) + 1] = 1.5f; },
       "back node (2, 1): normal has length 1.500000, expected 1 or 0"},
      {"label", [&](TwoLayerPanorama& p) { p.layer(kBack).label[at(p, 2, 1)] = 3; },
       "back node (2, 1): label 3 is not 0 (F) or 1 (B)"},
      {"reserved link",
       [&](TwoLayerPanorama& p) {
         uint8_t& l = p.layer(kFront).links[at(p, 0, 1)];
         l = SetLink(l, kDown, static_cast<Link>(3));
       },
       "front node (0, 1): down link has the reserved value 3"},
      {"link past the bottom row",
       [&](TwoLayerPanorama& p) {
         uint8_t& l = p.layer(kFront).links[at(p, 1, 2)];
         l = SetLink(l, kDown, Link::kFront);
       },
       "front node (1, 2): down link points outside the panorama (rows do not wrap)"},
      {"link to an absent node",
       [&](TwoLayerPanorama& p) {
         uint8_t& l = p.layer(kFront).links[at(p, 0, 0)];
         l = SetLink(l, kRight, Link::kBack);
       },
       "front node (0, 0): right link points at back node (1, 0), which is absent"},
      {"one-way link across layers",
       [&](TwoLayerPanorama& p) {
         uint8_t& l = p.layer(kBack).links[at(p, 2, 1)];
         l = SetLink(l, kLeft, Link::kNone);
       },
       "front node (1, 1): right link to back node (2, 1) is not mutual"},
      {"link answered by the wrong layer",
       [&](TwoLayerPanorama& p) {
         uint8_t& l = p.layer(kBack).links[at(p, 2, 1)];
         l = SetLink(l, kDown, Link::kFront);  // (2, 2) answers the front node (2, 1).
       },
       "back node (2, 1): down link to front node (2, 2) is not mutual"},
  };
  for (const Case& c : cases) {
    TwoLayerPanorama p = base();
    c.corrupt(p);
    const Status s = p.Validate();
    EXPECT_EQ(s.code(), StatusCode::kInvalidData) << c.what;
    EXPECT_EQ(s.message(), c.message) << c.what;
  }
}

// Random corruptions of valid panoramas: the fast scan accepts exactly what
// the node-by-node scan accepts.
TEST(TwoLayerTest, FastScanAgreesWithNodeByNodeScan) {
  std::mt19937 rng(7);
  const float specials[] = {0.0f,
                            -0.0f,
                            1.0f,
                            -1.0f,
                            0.5f,
                            1.0005f,
                            0.9995f,
                            1.002f,
                            0.998f,
                            std::numeric_limits<float>::infinity(),
                            std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::denorm_min(),
                            std::numeric_limits<float>::max()};
  const TwoLayerPanorama bases[] = {testing::MakeRoomPanorama(64, 32), FullyLinked(),
                                    FullyLinked(1, 3), FullyLinked(5, 1)};
  int accepted = 0, rejected = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    TwoLayerPanorama p = bases[trial % 4];
    const int edits = 1 + static_cast<int>(rng() % 3);
    for (int e = 0; e < edits; ++e) {
      LayerData& d = p.layer(static_cast<int>(rng() % 2));
      const size_t i = rng() % d.present.size();
      switch (rng() % 6) {
        case 0:
          d.present[i] = static_cast<uint8_t>(rng() % 3);
          break;
        case 1:
          d.rgb[3 * i + rng() % 3] = static_cast<uint8_t>(rng() % 2);
          break;
        case 2:
          d.depth_m[i] = specials[rng() % 13];
          break;
        case 3:
          d.normal[3 * i + rng() % 3] = specials[rng() % 13];
          break;
        case 4:
          d.label[i] = static_cast<uint8_t>(rng() % 3);
          break;
        default:
          d.links[i] =
              SetLink(d.links[i], static_cast<Direction>(rng() % 4), static_cast<Link>(rng() % 4));
          break;
      }
    }
    const bool fast = TwoLayerPanoramaTestAccess::FastScanAccepts(p);
    const Status slow = TwoLayerPanoramaTestAccess::NodeByNodeScan(p);
    ASSERT_EQ(fast, slow.ok()) << "trial " << trial << ": " << slow.ToString();
    // The scan in bands on several threads agrees, and so does the message.
    ASSERT_EQ(TwoLayerPanoramaTestAccess::FastScanAccepts(p, 3), fast) << "trial " << trial;
    ASSERT_EQ(p.Validate(3).ToString(), p.Validate().ToString()) << "trial " << trial;
    (fast ? accepted : rejected) += 1;
  }
  // Both outcomes are exercised.
  EXPECT_GT(accepted, 300);
  EXPECT_GT(rejected, 300);
}

// ValidateLinks() trusts the node values and checks the rest: with valid
// nodes and random link edits it agrees with Validate(), message included;
// a bad node value alone passes it.
TEST(TwoLayerTest, ValidateLinksAgreesWithValidateOnLinkEdits) {
  std::mt19937 rng(11);
  const TwoLayerPanorama bases[] = {testing::MakeRoomPanorama(64, 32), FullyLinked(),
                                    FullyLinked(1, 3), FullyLinked(5, 1)};
  int rejected = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    TwoLayerPanorama p = bases[trial % 4];
    const int edits = 1 + static_cast<int>(rng() % 3);
    for (int e = 0; e < edits; ++e) {
      LayerData& d = p.layer(static_cast<int>(rng() % 2));
      const size_t i = rng() % d.present.size();
      if (!d.present[i]) continue;  // Absent nodes keep zero links.
      d.links[i] =
          SetLink(d.links[i], static_cast<Direction>(rng() % 4), static_cast<Link>(rng() % 4));
    }
    const Status full = p.Validate(), links = p.ValidateLinks();
    ASSERT_EQ(full.ToString(), links.ToString()) << "trial " << trial;
    rejected += full.ok() ? 0 : 1;
  }
  EXPECT_GT(rejected, 300);
  TwoLayerPanorama p = FullyLinked();
  p.layer(kFront).depth_m[p.index(1, 1)] = -1.0f;
  EXPECT_FALSE(p.Validate().ok());
  EXPECT_TRUE(p.ValidateLinks().ok());
  p.layer(kFront).links[p.index(1, 1)] = 0;  // Its neighbours' links are no longer mutual.
  EXPECT_FALSE(p.ValidateLinks().ok());
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
