#include "reconstruct/depth/near_envelope.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace casual3d::depth {
namespace {

// Two colour regions split at x = 30; one anchor patch in each.
TEST(PropagateAnchors, FollowsColorEdges) {
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

// The coarse-to-fine start changes only the initial guess: the result must
// match a tightly converged single-level solve.
TEST(PropagateAnchors, CoarseToFineMatchesSingleLevel) {
  const int w = 150, h = 110;
  ImageF color(w, h, 3);
  ImageF anchors(w, h, 1, 0.0f);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> tex(-0.04f, 0.04f);
  std::uniform_int_distribution<int> pick(0, 49);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // Three colour regions (a disc, a band and the background).
      const bool disc = (x - 40) * (x - 40) + (y - 50) * (y - 50) < 900;
      const float base = disc ? 0.15f : (y > 80 ? 0.5f : 0.85f);
      for (int c = 0; c < 3; ++c) color.at(x, y, c) = base + (c == 1 ? 0.1f : 0.0f) + tex(rng);
      // Sparse anchors: about 2% of the pixels, depth smooth within a region.
      if (pick(rng) == 0) anchors.at(x, y) = disc ? 1.5f + 0.01f * x : (y > 80 ? 4.0f : 15.0f + 0.02f * y);
    }
  EnvelopeOptions single;
  single.variance_radius = 4;
  single.coarse_levels = 0;
  single.cg_tolerance = 1e-9;
  single.cg_max_iterations = 20000;
  const ImageF reference = PropagateAnchors(anchors, color, single);
  EnvelopeOptions multi;
  multi.variance_radius = 4;
  PropagationStats st_multi, st_single;
  const ImageF p = PropagateAnchors(anchors, color, multi, &st_multi);
  single.cg_tolerance = multi.cg_tolerance;
  PropagateAnchors(anchors, color, single, &st_single);
  ASSERT_EQ(p.width(), w);
  EXPECT_LT(st_multi.residual, multi.cg_tolerance);
  // The coarse guess saves iterations at the same tolerance.
  EXPECT_LT(st_multi.iterations, st_single.iterations);
  auto max_rel_diff = [&](const ImageF& q) {
    double m = 0;
    for (size_t i = 0; i < q.vector().size(); ++i)
      m = std::max(m, std::abs(1.0 - static_cast<double>(q.vector()[i]) / reference.vector()[i]));
    return m;
  };
  // Default tolerance: about 0.8% here, well inside the envelope's 10% margin (scale 0.9).
  EXPECT_LT(max_rel_diff(p), 0.015);
  // A tighter tolerance converges to the reference.
  multi.cg_tolerance = 1e-7;
  EXPECT_LT(max_rel_diff(PropagateAnchors(anchors, color, multi)), 2e-4);
}

TEST(EnvelopeOptions, RejectsBadCoarseLevels) {
  EnvelopeOptions o;
  o.coarse_levels = -1;
  EXPECT_FALSE(o.Check().ok());
  o.coarse_levels = 17;
  EXPECT_FALSE(o.Check().ok());
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
