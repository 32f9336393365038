#include "format/color_atlas.h"

#include <gtest/gtest.h>

#include <vector>

#include "format/colour_atlas.h"  // The deprecated names, tested below.
#include "format/testing/test_panoramas.h"

namespace casual3d {
namespace {

// 4 x 2: (0, 0) front and back, (1, 0) front only, (2, 0) back only, (3, 0)
// neither; row 1 front only.
TwoLayerPanorama SmallPanorama() {
  TwoLayerPanorama p(4, 2);
  auto set = [&](int x, int y, int l, uint8_t r, uint8_t g, uint8_t b) {
    LayerData& d = p.layer(l);
    const size_t i = p.index(x, y);
    d.present[i] = 1;
    d.depth_m[i] = l == kFront ? 1.0f : 2.0f;
    d.label[i] = static_cast<uint8_t>(l);
    d.rgb[3 * i] = r;
    d.rgb[3 * i + 1] = g;
    d.rgb[3 * i + 2] = b;
  };
  set(0, 0, kFront, 10, 11, 12);
  set(0, 0, kBack, 20, 21, 22);
  set(1, 0, kFront, 30, 31, 32);
  set(2, 0, kBack, 40, 41, 42);
  for (int x = 0; x < 4; ++x) set(x, 1, kFront, 50, static_cast<uint8_t>(x), 52);
  return p;
}

TEST(ColorAtlasTest, EachHalfShowsItsLayerAndFillsFromTheOtherLayer) {
  const TwoLayerPanorama p = SmallPanorama();
  const Image8 atlas = BuildColorAtlas(p);
  ASSERT_EQ(atlas.width(), 4);
  ASSERT_EQ(atlas.height(), 4);
  ASSERT_EQ(atlas.channels(), 3);
  auto rgb = [&](int x, int y) {
    return std::vector<int>{atlas.at(x, y, 0), atlas.at(x, y, 1), atlas.at(x, y, 2)};
  };
  using V = std::vector<int>;
  // Front half, row 0: own colours; (2, 0) takes the back colour; (3, 0) black.
  EXPECT_EQ(rgb(0, 0), (V{10, 11, 12}));
  EXPECT_EQ(rgb(1, 0), (V{30, 31, 32}));
  EXPECT_EQ(rgb(2, 0), (V{40, 41, 42}));
  EXPECT_EQ(rgb(3, 0), (V{0, 0, 0}));
  // Back half, row 0 (atlas row 2): own colours; (1, 0) takes the front colour.
  EXPECT_EQ(rgb(0, 2), (V{20, 21, 22}));
  EXPECT_EQ(rgb(1, 2), (V{30, 31, 32}));
  EXPECT_EQ(rgb(2, 2), (V{40, 41, 42}));
  EXPECT_EQ(rgb(3, 2), (V{0, 0, 0}));
  // Row 1 has front nodes only: both halves show them.
  for (int x = 0; x < 4; ++x) {
    EXPECT_EQ(rgb(x, 1), (V{50, x, 52}));
    EXPECT_EQ(rgb(x, 3), (V{50, x, 52}));
  }
}

TEST(ColorAtlasTest, RgbaMatchesRgbWithOpaqueAlpha) {
  const TwoLayerPanorama p = testing::MakeRoomPanorama(64, 32);
  const Image8 rgb = BuildColorAtlas(p, 3);
  const Image8 rgba = BuildColorAtlas(p, 4);
  ASSERT_EQ(rgba.width(), 64);
  ASSERT_EQ(rgba.height(), 64);
  ASSERT_EQ(rgba.channels(), 4);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      for (int c = 0; c < 3; ++c) ASSERT_EQ(rgba.at(x, y, c), rgb.at(x, y, c));
      ASSERT_EQ(rgba.at(x, y, 3), 255);
    }
  }
}

TEST(ColorAtlasTest, RefusesUnsupportedChannelCounts) {
  const TwoLayerPanorama p = SmallPanorama();
  EXPECT_TRUE(BuildColorAtlas(p, 1).empty());
  EXPECT_TRUE(BuildColorAtlas(p, 5).empty());
}

// format/colour_atlas.h keeps the earlier name working (docs/SDK.md).
TEST(ColorAtlasTest, DeprecatedNameBuildsTheSameAtlas) {
  const TwoLayerPanorama p = SmallPanorama();
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
  const Image8 old_rgb = BuildColourAtlas(p), old_rgba = BuildColourAtlas(p, 4);
#pragma GCC diagnostic pop
  EXPECT_EQ(old_rgb.vector(), BuildColorAtlas(p).vector());
  EXPECT_EQ(old_rgba.vector(), BuildColorAtlas(p, 4).vector());
}

}  // namespace
}  // namespace casual3d
