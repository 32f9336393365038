#include "reconstruct/depth/near_envelope.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace casual3d::depth {
namespace {

// Two colour regions split at x = 30; one anchor patch in each.
TEST(PropagateAnchors, FollowsColourEdges) {
  const int w = 60, h = 40;
  ImageF color(w, h, 3);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> tex(-0.05f, 0.05f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) color.at(x, y, c) = (x < 30 ? 0.2f : 0.8f) + tex(rng);
  ImageF anchors(w, h, 1, 0.0f);
  for (int y = 5; y < 9; ++y)
    for (int x = 5; x < 9; ++x) anchors.at(x, y) = 2.0f;
  for (int y = 30; y < 34; ++y)
    for (int x = 50; x < 54; ++x) anchors.at(x, y) = 8.0f;
  EnvelopeOptions o;
  o.variance_radius = 3;
  PropagationStats st;
  const ImageF p = PropagateAnchors(anchors, color, o, &st);
  ASSERT_FALSE(p.empty());
  EXPECT_EQ(st.anchors, 32);
  EXPECT_LT(st.residual, 1e-4);
  // Far from its anchor but inside its colour region, each side keeps its depth.
  EXPECT_NEAR(p.at(25, 35), 2.0f, 0.1f);
  EXPECT_NEAR(p.at(35, 2), 8.0f, 0.6f);
  EXPECT_NEAR(p.at(6, 6), 2.0f, 0.02f);
}

TEST(PropagateAnchors, ReturnsEmptyWithoutAnchors) {
  EXPECT_TRUE(PropagateAnchors(ImageF(8, 8, 1, 0.0f), ImageF(8, 8, 3, 0.5f), EnvelopeOptions()).empty());
}

TEST(MinFilter, MatchesBruteForce) {
  const int w = 37, h = 23, diam = 7;
  ImageF img(w, h, 1);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0, 10);
  for (float& v : img.vector()) v = u(rng);
  const ImageF out = MinFilter(img, diam);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float m = 1e9f;
      for (int v = std::max(0, y - 3); v <= std::min(h - 1, y + 3); ++v)
        for (int q = std::max(0, x - 3); q <= std::min(w - 1, x + 3); ++q) m = std::min(m, img.at(q, v));
      ASSERT_EQ(out.at(x, y), m);
    }
}

TEST(FinalizeEnvelope, ScalesAndErodesTowardsTheNearSide) {
  ImageF prop(100, 100, 1, 10.0f);
  for (int y = 40; y < 60; ++y)
    for (int x = 40; x < 60; ++x) prop.at(x, y) = 2.0f;
  EnvelopeOptions o;  // 3% of the diagonal (141) -> diameter 5 (rounded to odd).
  const ImageF env = FinalizeEnvelope(prop, o);
  EXPECT_FLOAT_EQ(env.at(5, 5), 9.0f);
  EXPECT_FLOAT_EQ(env.at(50, 50), 1.8f);
  EXPECT_FLOAT_EQ(env.at(38, 50), 1.8f);  // Within 2 pixels of the near square: pulled forward.
  EXPECT_FLOAT_EQ(env.at(37, 50), 9.0f);
}

}  // namespace
}  // namespace casual3d::depth
