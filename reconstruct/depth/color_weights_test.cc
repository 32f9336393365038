#include "reconstruct/depth/color_weights.h"

#include <gtest/gtest.h>

#include <cmath>

namespace casual3d::depth {
namespace {

TEST(ColorWeights, SplitsChannelsIntoPaddedPlanes) {
  ImageF c(3, 2, 3);
  for (int i = 0; i < 18; ++i) c.data()[i] = 0.01f * i;
  const ColorPlanes p = SplitColor(c, 4);
  ASSERT_EQ(p.r.size(), 10u);
  ASSERT_EQ(p.g.size(), 10u);
  ASSERT_EQ(p.b.size(), 10u);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(p.r[i], c.data()[3 * i]);
    EXPECT_EQ(p.g[i], c.data()[3 * i + 1]);
    EXPECT_EQ(p.b[i], c.data()[3 * i + 2]);
  }
  for (int i = 6; i < 10; ++i) EXPECT_EQ(p.r[i] + p.g[i] + p.b[i], 0.0f);
  EXPECT_THROW(SplitColor(ImageF(2, 2, 1)), std::invalid_argument);
}

TEST(ColorWeights, AreGaussianInTheColorDistance) {
  const float r[] = {0.5f, 0.6f, 0.1f, 0.5f, 0.9f};
  const float g[] = {0.5f, 0.5f, 0.2f, 0.45f, 0.0f};
  const float b[] = {0.5f, 0.4f, 0.3f, 0.5f, 1.0f};
  const float c0[] = {0.5f, 0.5f, 0.5f};
  const float sigma = 0.06f, inv2s2 = 1.0f / (2 * sigma * sigma);
  float w[5];
  ColorWeights(r, g, b, 5, c0, inv2s2, w);
  for (int i = 0; i < 5; ++i) {
    const double d2 = std::pow(r[i] - 0.5, 2) + std::pow(g[i] - 0.5, 2) + std::pow(b[i] - 0.5, 2);
    const double expect = std::exp(-d2 * inv2s2);
    EXPECT_NEAR(w[i], expect, 1e-6 * std::max(1.0, expect) + 1e-30) << i;
  }
  EXPECT_EQ(w[0], 1.0f);
  EXPECT_GT(w[3], w[1]);
}

}  // namespace
}  // namespace casual3d::depth
