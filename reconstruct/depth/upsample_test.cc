#include "reconstruct/depth/upsample.h"

#include <set>

#include <gtest/gtest.h>

namespace casual3d::depth {
namespace {

TEST(JointBilateralMedianUpsample, NoMixedDepthsAndEdgesFollowTheGuide) {
  // Low resolution 20x15 with a depth step at low x = 10; the full-resolution
  // guide (80x60) has its colour edge at x = 41 (between low pixels).
  const int lw = 20, lh = 15, hw = 80, hh = 60;
  ImageF low(lw, lh, 1), low_c(lw, lh, 3), high_c(hw, hh, 3);
  for (int y = 0; y < lh; ++y)
    for (int x = 0; x < lw; ++x) {
      low.at(x, y) = x < 10 ? 2.0f : 7.0f;
      for (int c = 0; c < 3; ++c) low_c.at(x, y, c) = x < 10 ? 0.1f : 0.9f;
    }
  for (int y = 0; y < hh; ++y)
    for (int x = 0; x < hw; ++x)
      for (int c = 0; c < 3; ++c) high_c.at(x, y, c) = x < 40 ? 0.1f : 0.9f;
  const ImageF up = JointBilateralMedianUpsample(low, low_c, high_c, UpsampleOptions());
  ASSERT_EQ(up.width(), hw);
  std::set<float> values(up.vector().begin(), up.vector().end());
  EXPECT_EQ(values, (std::set<float>{2.0f, 7.0f}));
  for (int y = 0; y < hh; ++y)
    for (int x = 0; x < hw; ++x) ASSERT_EQ(up.at(x, y), x < 40 ? 2.0f : 7.0f) << x << "," << y;
}

TEST(JointBilateralMedianUpsample, IgnoresInvalidSamples) {
  ImageF low(4, 4, 1, 0.0f), lc(4, 4, 3, 0.5f), hc(8, 8, 3, 0.5f);
  low.at(0, 0) = 3.0f;
  const ImageF up = JointBilateralMedianUpsample(low, lc, hc, UpsampleOptions());
  EXPECT_EQ(up.at(0, 0), 3.0f);
  EXPECT_EQ(up.at(7, 7), 0.0f);  // No valid sample within the radius.
}

}  // namespace
}  // namespace casual3d::depth
