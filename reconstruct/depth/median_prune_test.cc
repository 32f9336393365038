#include "reconstruct/depth/median_prune.h"

#include <random>

#include <gtest/gtest.h>

namespace casual3d::depth {
namespace {

const LabelGrid kGrid{1.0 / 0.5, 1.0 / 50.0, 220};

float LabelDepth(int k) { return static_cast<float>(kGrid.DepthOf(k)); }

TEST(MedianPrune, RemovesSaltAndPepperKeepsTheSurface) {
  const int w = 60, h = 40;
  ImageF d(w, h, 1, LabelDepth(100));
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> ux(0, w - 1), uy(0, h - 1), ul(0, 60);
  std::vector<std::pair<int, int>> noise;
  for (int i = 0; i < 60; ++i) {
    const int x = ux(rng), y = uy(rng);
    d.at(x, y) = LabelDepth(ul(rng));  // Labels 0..60: far nearer than the surface.
    noise.emplace_back(x, y);
  }
  MedianPruneOptions o;
  const ImageF out = MedianPrune(d, kGrid, o, 2);
  for (auto [x, y] : noise) EXPECT_EQ(out.at(x, y), 0.0f) << x << "," << y;
  int kept = 0;
  for (float v : out.vector()) kept += v > 0;
  EXPECT_GE(kept, w * h - 60);
}

TEST(MedianPrune, DropsIsolatedSurvivorsAndKeepsOneLabelJitter) {
  ImageF d(20, 20, 1, 0.0f);
  d.at(10, 10) = LabelDepth(50);  // Alone in an empty window.
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) d.at(x, y) = LabelDepth(200 + ((x + y) % 2));  // One-label jitter, far away.
  const ImageF out = MedianPrune(d, kGrid, MedianPruneOptions());
  EXPECT_EQ(out.at(10, 10), 0.0f);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) EXPECT_GT(out.at(x, y), 0.0f);
}

TEST(BilateralMedianPrune, RemovesAFloaterButKeepsAThinStructureOfItsOwnColor) {
  const int w = 80, h = 60;
  ImageF d(w, h, 1, LabelDepth(150));
  ImageF c(w, h, 3, 0.5f);
  // A 12x12 floater (nearer) on a same-coloured background: an outlier.
  for (int y = 10; y < 22; ++y)
    for (int x = 10; x < 22; ++x) d.at(x, y) = LabelDepth(60);
  // A 2-pixel wide pole (nearer) with a distinct colour: real content.
  for (int y = 0; y < h; ++y)
    for (int x = 50; x < 52; ++x) {
      d.at(x, y) = LabelDepth(40);
      c.at(x, y, 0) = 0.9f;
      c.at(x, y, 1) = 0.2f;
    }
  MedianPruneOptions o;
  o.large_radius = 12;
  const ImageF out = BilateralMedianPrune(d, c, kGrid, o, 2);
  int floater_kept = 0, pole_kept = 0;
  for (int y = 10; y < 22; ++y)
    for (int x = 10; x < 22; ++x) floater_kept += out.at(x, y) > 0;
  for (int y = 0; y < h; ++y)
    for (int x = 50; x < 52; ++x) pole_kept += out.at(x, y) > 0;
  EXPECT_EQ(floater_kept, 0);
  EXPECT_EQ(pole_kept, 2 * h);
  EXPECT_GT(out.at(70, 50), 0.0f);
}

TEST(MedianPrune, RejectsBadOptions) {
  MedianPruneOptions o;
  o.band_low = 1.2;
  EXPECT_FALSE(o.Check().ok());
  o = MedianPruneOptions();
  o.large_radius = 0;
  EXPECT_FALSE(o.Check().ok());
}

}  // namespace
}  // namespace casual3d::depth
