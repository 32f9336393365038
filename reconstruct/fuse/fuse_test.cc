#include "reconstruct/fuse/fuse.h"

#include <cmath>

#include <gtest/gtest.h>

namespace casual3d::fuse {
namespace {

// A 256x128 panorama: background at `background` m (4 by default)
// everywhere, a foreground square at 1 m over columns [100, 140) and rows
// [50, 80). The back stitch saw the
// background behind the square's first and last `seen` columns and repeats the
// front elsewhere. The front's background pixels right next to the square
// carry the square's colour (a fringe).
struct Scene {
  static constexpr int W = 256, H = 128;
  Image8 front_rgb{W, H, 3, 0}, back_rgb{W, H, 3, 0};
  ImageF front_depth{W, H, 1, 0.0f}, back_depth{W, H, 1, 0.0f};

  static bool InSquare(int x, int y) { return x >= 100 && x < 140 && y >= 50 && y < 80; }

  explicit Scene(int seen, float background = 4.0f) {
    for (int y = 0; y < H; ++y) {
      for (int x = 0; x < W; ++x) {
        const bool sq = InSquare(x, y);
        front_depth.at(x, y) = sq ? 1.0f : background;
        front_rgb.at(x, y, 0) = sq ? 250 : 20;
        back_depth.at(x, y) = background;  // Redundant where the front is the background.
        back_rgb.at(x, y, 0) = 20;
        const bool seen_behind = sq && (x < 100 + seen || x >= 140 - seen);
        if (sq && !seen_behind) back_depth.at(x, y) = 0.0f;
        // Fringe: background pixels touching the square horizontally.
        if (!sq && y >= 50 && y < 80 && (x == 99 || x == 140)) front_rgb.at(x, y, 0) = 200;
      }
    }
  }
  FuseInput Input() const { return {&front_rgb, &front_depth, &back_rgb, &back_depth, {}}; }
};

TEST(FuseTest, RemovesRedundancyLinksSurfacesAndKeepsEdgesOpen) {
  Scene scene(3);
  FuseOptions options;
  options.expansion_fraction = 0;  // No growth: check steps 1 and 2 alone.
  options.fringe_fraction = 0;
  FuseStats stats;
  const TwoLayerPanorama pano = Fuse(scene.Input(), options, &stats);
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  const int W = Scene::W, H = Scene::H;
  EXPECT_EQ(stats.front_nodes, W * H);
  // Back nodes: only behind the square where the back stitch saw the background.
  EXPECT_EQ(stats.back_nodes_redundant, W * H - 40 * 30);
  long back = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) back += pano.present(kBack, x, y);
  EXPECT_EQ(back, 2 * 3 * 30);
  const LayerData& F = pano.layer(kFront);
  const LayerData& B = pano.layer(kBack);
  // The square's left edge is open: the foreground links nothing to its left...
  EXPECT_EQ(GetLink(F.links[pano.index(100, 60)], kLeft), Link::kNone);
  // ...and the background continues into the back layer behind the square.
  EXPECT_EQ(GetLink(F.links[pano.index(99, 60)], kRight), Link::kBack);
  EXPECT_EQ(GetLink(B.links[pano.index(100, 60)], kLeft), Link::kFront);
  EXPECT_EQ(GetLink(B.links[pano.index(101, 60)], kLeft), Link::kBack);
  // Inside surfaces everything is linked, across the seam too.
  EXPECT_EQ(GetLink(F.links[pano.index(W - 1, 10)], kRight), Link::kFront);
  EXPECT_EQ(GetLink(F.links[pano.index(120, 60)], kDown), Link::kFront);
  // Poles: nothing above row 0.
  EXPECT_EQ(GetLink(F.links[pano.index(10, 0)], kUp), Link::kNone);
}

TEST(FuseTest, GrowsTheBackLayerBehindTheForeground) {
  Scene scene(3);
  FuseOptions options;
  options.expansion_fraction = 10.0 / Scene::W;  // 10 rings.
  options.fringe_fraction = 0;
  FuseStats stats;
  const TwoLayerPanorama pano = Fuse(scene.Input(), options, &stats);
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  // Back nodes now reach 3 + 8 columns in from each side of the square, at
  // the background's depth, and never outside the square: the 10 rings hold
  // for a background far behind, and a moving eye opens 1 - 1/4 of that gap
  // between the square at 1 m and the background at 4 m (8.5 rings).
  for (int x = 100; x < 140; ++x) {
    const bool expect_back = x < 111 || x >= 129;
    EXPECT_EQ(pano.present(kBack, x, 65), expect_back) << "column " << x;
    if (expect_back) {
      EXPECT_FLOAT_EQ(pano.layer(kBack).depth_m[pano.index(x, 65)], 4.0f);
    }
  }
  for (int x = 0; x < Scene::W; ++x) {
    if (x < 100 || x >= 140) {
      EXPECT_FALSE(pano.present(kBack, x, 65));
    }
  }
  // Rows above and below the square grow too (vertical edges of the square).
  EXPECT_TRUE(pano.present(kBack, 120, 50));
  EXPECT_GT(stats.back_nodes_hallucinated, 2 * 8 * 30);
}

TEST(FuseTest, GrowsASurfaceJustBehindTheForegroundOnlyARing) {
  // A background 10% behind the square (the noisy far side of a trunk, say):
  // the eye opens 1 - 1/1.1 of the far-background gap there, 1.9 rings of 10.
  Scene scene(3, 1.1f);
  FuseOptions options;
  options.expansion_fraction = 10.0 / Scene::W;
  options.fringe_fraction = 0;
  FuseStats stats;
  const TwoLayerPanorama pano = Fuse(scene.Input(), options, &stats);
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  for (int x = 100; x < 140; ++x) {
    const bool expect_back = x < 104 || x >= 136;  // 3 seen + 1 grown each side.
    EXPECT_EQ(pano.present(kBack, x, 65), expect_back) << "column " << x;
  }
}

TEST(FuseTest, TheBackgroundTakesThePixelsASurfaceJustBehindCannotFill) {
  // The square's far side, 10% behind it, shows as a strip of front nodes at
  // 1.1 m over columns [96, 100) (a trunk's noisy silhouette); nothing was
  // seen behind the square. The strip grows one ring behind the square (with
  // every ring it covered columns 100-109); the background at 4 m grows in
  // over the square's top and bottom rows and from its right.
  Scene scene(0);
  for (int y = 50; y < 80; ++y) {
    for (int x = 96; x < 100; ++x) {
      scene.front_depth.at(x, y) = 1.1f;
      scene.back_depth.at(x, y) = 0.0f;
    }
  }
  FuseOptions options;
  options.expansion_fraction = 10.0 / Scene::W;
  options.fringe_fraction = 0;
  const TwoLayerPanorama pano = Fuse(scene.Input(), options);
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  const LayerData& B = pano.layer(kBack);
  int strip_behind = 0, background_behind = 0;
  for (int y = 50; y < 80; ++y) {
    for (int x = 100; x < 140; ++x) {
      const size_t i = pano.index(x, y);
      if (!B.present[i]) continue;
      strip_behind += B.depth_m[i] < 1.2f;
      background_behind += B.depth_m[i] > 3.5f;
      // Beyond the strip's one ring, nothing of its depth.
      if (x > 100) {
        EXPECT_GT(B.depth_m[i], 1.2f) << x << "," << y;
      }
    }
  }
  EXPECT_LE(strip_behind, 30);  // Column 100 at most.
  // The background's rings from above reach row 51 behind columns 102-109.
  for (int x = 102; x < 110; ++x) EXPECT_GT(B.depth_m[pano.index(x, 51)], 3.0f) << "column " << x;
  EXPECT_GT(background_behind, 8 * 30);
}

TEST(FuseTest, RemovesColorFringes) {
  Scene scene(3);
  FuseOptions options;
  options.expansion_fraction = 0;
  options.fringe_fraction = 2.0 / Scene::W;
  FuseStats stats;
  const TwoLayerPanorama pano = Fuse(scene.Input(), options, &stats);
  ASSERT_TRUE(pano.Validate().ok());
  const LayerData& F = pano.layer(kFront);
  for (int y = 50; y < 80; ++y) {
    EXPECT_EQ(F.rgb[3 * pano.index(99, y)], 20) << "row " << y;
    EXPECT_EQ(F.rgb[3 * pano.index(140, y)], 20) << "row " << y;
    EXPECT_EQ(F.label[pano.index(99, y)], static_cast<uint8_t>(NodeLabel::kB));
    // The foreground keeps its colour and label.
    EXPECT_EQ(F.rgb[3 * pano.index(100, y)], 250);
    EXPECT_EQ(F.label[pano.index(100, y)], static_cast<uint8_t>(NodeLabel::kF));
  }
  EXPECT_GT(stats.front_nodes_relabelled, 0);
}

TEST(FuseTest, RejectsMismatchedInputs) {
  Scene scene(1);
  ImageF small(10, 5, 1, 1.0f);
  FuseInput input = scene.Input();
  input.back_depth_m = &small;
  EXPECT_THROW(Fuse(input, FuseOptions()), std::invalid_argument);
  FuseOptions bad;
  bad.tau_dratio = 1.5;
  EXPECT_THROW(Fuse(scene.Input(), bad), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::fuse
