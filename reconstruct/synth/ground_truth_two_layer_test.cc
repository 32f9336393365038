#include "reconstruct/synth/ground_truth_two_layer.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "reconstruct/synth/default_scene.h"

namespace casual3d::synth {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Sets one pixel's layer (0 front, 1 back): colour grey, depth z, normal +Z.
void SetSurface(GroundTruthPanorama* gt, int x, int y, int layer, float z) {
  const int base = layer == 0 ? kFrontR : kBackR;
  for (int k = 0; k < 3; ++k) gt->pixels.at(x, y, base + k) = 0.2f;
  gt->pixels.at(x, y, base + 3) = z;
  gt->pixels.at(x, y, base + 4) = 0;
  gt->pixels.at(x, y, base + 5) = 0;
  gt->pixels.at(x, y, base + 6) = std::isfinite(z) ? 1.0f : 0.0f;
}

TEST(GroundTruthTwoLayerTest, DropsRedundantBacksAndLinksSimilarDepths) {
  GroundTruthPanorama gt;
  gt.pixels = ImageF(4, 2, kNumPanoramaChannels);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      SetSurface(&gt, x, y, 0, 2.0f);
      SetSurface(&gt, x, y, 1, kNaN);
    }
  // (1,0): a near object at 1 m with the wall at 2 m behind it (ratio 0.5: kept).
  SetSurface(&gt, 1, 0, 0, 1.0f);
  SetSurface(&gt, 1, 0, 1, 2.0f);
  // (2,0): a back surface only 10% behind (ratio 0.91 > 0.75: dropped).
  SetSurface(&gt, 2, 0, 1, 2.2f);
  // (3,1): sky in front.
  SetSurface(&gt, 3, 1, 0, kInf);

  TwoLayerOptions options;
  ASSERT_TRUE(options.Check().ok());
  const TwoLayerPanorama pano = GroundTruthToTwoLayer(gt, options);
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  EXPECT_TRUE(pano.present(kBack, 1, 0));
  EXPECT_FALSE(pano.present(kBack, 2, 0));
  EXPECT_FALSE(pano.present(kBack, 0, 0));
  EXPECT_EQ(pano.layer(kBack).label[pano.index(1, 0)], static_cast<uint8_t>(NodeLabel::kB));
  // Sky clamped to 1000 m, unlit.
  EXPECT_FLOAT_EQ(pano.layer(kFront).depth_m[pano.index(3, 1)], 1000.0f);
  EXPECT_EQ(pano.layer(kFront).normal[3 * pano.index(3, 1) + 2], 0.0f);
  // sRGB of linear 0.2 is 124.
  EXPECT_EQ(pano.layer(kFront).rgb[0], 124);

  auto link = [&](int l, int x, int y, Direction d) {
    return GetLink(pano.layer(l).links[pano.index(x, y)], d);
  };
  // Front (0,0) at 2 m: not linked to the 1 m front of (1,0) but to its 2 m back node.
  EXPECT_EQ(link(kFront, 0, 0, kRight), Link::kBack);
  EXPECT_EQ(link(kBack, 1, 0, kLeft), Link::kFront);
  EXPECT_EQ(link(kBack, 1, 0, kRight), Link::kFront);  // To (2,0) front at 2 m.
  EXPECT_EQ(link(kFront, 1, 0, kRight), Link::kNone);
  EXPECT_EQ(link(kFront, 1, 0, kDown), Link::kNone);    // 1 m vs 2 m below.
  EXPECT_EQ(link(kFront, 0, 0, kDown), Link::kFront);
  // The seam wraps: (3,0) links right to (0,0).
  EXPECT_EQ(link(kFront, 3, 0, kRight), Link::kFront);
  EXPECT_EQ(link(kFront, 0, 0, kLeft), Link::kFront);
  // Sky is not linked to a surface at 2 m.
  EXPECT_EQ(link(kFront, 3, 1, kLeft), Link::kNone);
  EXPECT_EQ(link(kFront, 3, 1, kUp), Link::kNone);
}

TEST(GroundTruthTwoLayerTest, RenderedScenePanoramaIsValid) {
  const Scene scene = BuildDefaultScene(1);
  PanoramaFrame frame;
  frame.centre[1] = 1.5;
  const GroundTruthPanorama gt = RenderGroundTruthPanorama(scene, frame, 256, 128, 0);
  const TwoLayerPanorama pano = GroundTruthToTwoLayer(gt, TwoLayerOptions());
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  int fronts = 0, backs = 0, sky = 0;
  // Rays into the ground have no second surface; rays into sky have none either.
  EXPECT_TRUE(std::isnan(gt.pixels.at(128, 127, kBackZ)));
  EXPECT_TRUE(std::isnan(gt.pixels.at(128, 0, kBackZ)));
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 256; ++x) {
      fronts += pano.present(kFront, x, y);
      backs += pano.present(kBack, x, y);
      sky += pano.layer(kFront).depth_m[pano.index(x, y)] == 1000.0f;
    }
  EXPECT_EQ(fronts, 256 * 128);
  // The near objects have something behind them; the sky covers the upper half.
  EXPECT_GT(backs, 2000);
  std::printf("two-layer ground truth 256x128: %d back nodes, %d sky pixels\n", backs, sky);
  EXPECT_LT(backs, 256 * 128 / 4);
  EXPECT_GT(sky, 256 * 128 / 4);
  EXPECT_LT(sky, 256 * 128 / 2 + 256 * 6);
  // Straight ahead at the horizon: the rods, pedestal or blue ball; straight down: the ground 1.5 m away.
  const float down = gt.pixels.at(128, 127, kFrontZ);
  EXPECT_NEAR(down, 1.5f, 0.01f);
  EXPECT_NEAR(gt.pixels.at(128, 127, kFrontNY), 1.0f, 1e-4f);
}

}  // namespace
}  // namespace casual3d::synth
