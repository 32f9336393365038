#include "reconstruct/fuse/seal.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "format/mesh_builder.h"
#include "reconstruct/fuse/fuse.h"

namespace casual3d::fuse {
namespace {

struct Input {
  Image8 front_rgb, back_rgb;
  ImageF front_depth, back_depth;
};

Input Flat(int W, int H) {
  Input in{Image8(W, H, 3, 128), Image8(W, H, 3, 0), ImageF(W, H, 1, 0.0f), ImageF(W, H, 1, 0.0f)};
  return in;
}

TwoLayerPanorama FuseInputs(const Input& in, double expansion = 0.01) {
  FuseOptions o;
  o.expansion_fraction = expansion;
  return Fuse({&in.front_rgb, &in.front_depth, &in.back_rgb, &in.back_depth, PanoramaFrame()}, o);
}

TEST(SealTears, NoisyContinuousSurfaceIsClosed) {
  // A wall at 2 m with 4% depth noise: fusion cuts links whose ratio falls
  // below 0.95 and the back layer's growth takes link slots; the quads left
  // open are holes seen from the centre.
  const int W = 128, H = 64;
  Input in = Flat(W, H);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> noise(-0.04f, 0.04f);
  for (int y = 16; y < 48; ++y)
    for (int x = 0; x < W; ++x) in.front_depth.at(x, y) = 2.0f * std::exp(noise(rng));
  TwoLayerPanorama pano = FuseInputs(in);
  const int64_t before = CountOpenQuads(pano);
  ASSERT_GT(before, 20);  // The fused noisy wall has tears.
  const SealStats stats = SealTears(&pano);
  EXPECT_EQ(stats.open_quads_before, before);
  EXPECT_EQ(stats.open_quads_after, CountOpenQuads(pano));
  EXPECT_EQ(stats.open_quads_after, 0);
  EXPECT_GT(stats.links_made + stats.back_nodes_added, 0);
  EXPECT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
}

TEST(SealTears, SmallStepOfOneSurfaceIsClosedByTheFrontLayerItself) {
  // A wall with a 8% step (ratio 0.926, above continuous_ratio 0.9, below
  // tau_dratio 0.95): fusion cuts the front links across it and grows the
  // farther side behind the nearer one, which closes the quads seen from the
  // centre but leaves a slit that opens as soon as the eye moves. The
  // front-surface round links the two sides in the front layer.
  const int W = 64, H = 32;
  Input in = Flat(W, H);
  for (int y = 4; y < 28; ++y)
    for (int x = 0; x < W; ++x) in.front_depth.at(x, y) = x < 30 ? 2.0f : 2.16f;
  TwoLayerPanorama pano = FuseInputs(in);
  const auto front_only_open = [&] {
    int open = 0;
    for (int y = 4; y + 1 < 28; ++y)
      for (int x = 0; x < W; ++x)
        open += QuadCoverage(pano, x, y, true, 1u << kBack) != 0xFu;
    return open;
  };
  ASSERT_EQ(CountOpenQuads(pano), 0);  // Closed from the centre by the grown back layer.
  ASSERT_GT(front_only_open(), 0);     // But not by the front surface itself.
  const SealStats stats = SealTears(&pano);
  EXPECT_GT(stats.front_surface_open_quads_before, 0);
  EXPECT_EQ(stats.front_surface_open_quads_after, 0);
  EXPECT_EQ(front_only_open(), 0);
  EXPECT_EQ(CountOpenQuads(pano), 0);
  EXPECT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
}

TEST(SealTears, DepthEdgeWithoutBackLayerGetsTheFarSurfaceBehind) {
  // A near square (1 m) on a wall (3 m), fused without back-layer growth:
  // the quads across its border are open. Sealing extends the wall behind
  // the square's border (back nodes at the wall's depth), never a link
  // across the edge (ratio 1/3).
  const int W = 64, H = 32;
  Input in = Flat(W, H);
  for (int y = 4; y < 28; ++y)
    for (int x = 0; x < W; ++x) in.front_depth.at(x, y) = (x >= 20 && x < 40 && y >= 10 && y < 22) ? 1.0f : 3.0f;
  TwoLayerPanorama pano = FuseInputs(in, 0.0);
  ASSERT_GT(CountOpenQuads(pano), 0);
  const SealStats stats = SealTears(&pano);
  EXPECT_EQ(stats.open_quads_after, 0);
  EXPECT_GT(stats.back_nodes_added, 0);
  EXPECT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  const LayerData& F = pano.layer(kFront);
  const LayerData& B = pano.layer(kBack);
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const size_t i = pano.index(x, y);
      if (B.present[i]) EXPECT_FLOAT_EQ(B.depth_m[i], 3.0f) << x << "," << y;
      // No front link joins the square and the wall.
      if (F.present[i] && F.depth_m[i] == 1.0f) {
        for (int d = 0; d < kNumDirections; ++d) {
          int nx, ny;
          if (!pano.Neighbour(x, y, static_cast<Direction>(d), &nx, &ny)) continue;
          if (GetLink(F.links[i], static_cast<Direction>(d)) == Link::kFront)
            EXPECT_FLOAT_EQ(F.depth_m[pano.index(nx, ny)], 1.0f);
        }
      }
    }
  }
}

TEST(SealTears, ThreeSurfacesBehindAnEdgeAreClosed) {
  // A near bar (1 m) in front of the junction of a wall (2 m) and a far
  // wall (6 m): behind the bar's border three surfaces meet, which two
  // layers cannot hold; the second round links the two walls behind the bar.
  const int W = 64, H = 32;
  Input in = Flat(W, H);
  for (int y = 2; y < 30; ++y)
    for (int x = 0; x < W; ++x) {
      const bool bar = y >= 8 && y < 24 && x >= 28 && x < 36;
      in.front_depth.at(x, y) = bar ? 1.0f : (y < 16 ? 2.0f : 6.0f);
    }
  TwoLayerPanorama pano = FuseInputs(in);
  ASSERT_GT(CountOpenQuads(pano), 0);
  SealStats stats = SealTears(&pano);
  EXPECT_EQ(stats.open_quads_after, 0);
  EXPECT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  // No link ever joins the bar to anything behind it.
  const LayerData& F = pano.layer(kFront);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = pano.index(x, y);
      if (!F.present[i] || F.depth_m[i] != 1.0f) continue;
      for (int d = 0; d < kNumDirections; ++d) {
        const Link l = GetLink(F.links[i], static_cast<Direction>(d));
        if (l == Link::kNone) continue;
        int nx, ny;
        ASSERT_TRUE(pano.Neighbour(x, y, static_cast<Direction>(d), &nx, &ny));
        EXPECT_FLOAT_EQ(pano.layer(l == Link::kFront ? kFront : kBack).depth_m[pano.index(nx, ny)], 1.0f);
      }
    }
}

TEST(SealTears, ClosedPanoramaIsUnchanged) {
  const int W = 64, H = 32;
  Input in = Flat(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) in.front_depth.at(x, y) = 2.0f + 0.01f * x;
  TwoLayerPanorama pano = FuseInputs(in);
  const TwoLayerPanorama before = pano;
  const SealStats stats = SealTears(&pano);
  EXPECT_EQ(stats.open_quads_before, 0);
  EXPECT_TRUE(pano == before);
}

TEST(SealTears, QuadCoverageQuarters) {
  // One quad, front only: the four links give the whole quad; an L at
  // corner C gives its left and bottom quarters.
  TwoLayerPanorama pano(4, 2);
  LayerData& F = pano.layer(kFront);
  for (size_t i = 0; i < F.present.size(); ++i) {
    F.present[i] = 1;
    F.depth_m[i] = 1.0f;
  }
  auto link = [&](int x, int y, Direction d) {
    int nx, ny;
    ASSERT_TRUE(pano.Neighbour(x, y, d, &nx, &ny));
    F.links[pano.index(x, y)] = SetLink(F.links[pano.index(x, y)], d, Link::kFront);
    F.links[pano.index(nx, ny)] = SetLink(F.links[pano.index(nx, ny)], Opposite(d), Link::kFront);
  };
  link(0, 1, kUp);
  link(0, 1, kRight);
  EXPECT_EQ(QuadCoverage(pano, 0, 0), kQuarterLeft | kQuarterBottom);
  link(1, 0, kDown);
  link(0, 0, kRight);
  EXPECT_EQ(QuadCoverage(pano, 0, 0), 0xFu);
  EXPECT_TRUE(pano.Validate().ok());
}

TEST(SealOptions, Check) {
  SealOptions o;
  EXPECT_TRUE(o.Check().ok());
  o.tau_dratio = 0.5;
  EXPECT_FALSE(o.Check().ok());
  o = SealOptions();
  o.max_passes = 0;
  EXPECT_FALSE(o.Check().ok());
  EXPECT_THROW(SealTears(nullptr, o), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::fuse
