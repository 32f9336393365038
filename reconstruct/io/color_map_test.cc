#include "reconstruct/io/color_map.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace casual3d::io {
namespace {

int Lightness(const uint8_t c[3]) { return 2 * c[0] + 5 * c[1] + c[2]; }

TEST(ColorMapTest, EndsAndClamping) {
  uint8_t a[3], b[3];
  DepthRampColor(0.0, a);
  DepthRampColor(-3.0, b);
  EXPECT_EQ(a[0], b[0]);
  EXPECT_EQ(a[2], b[2]);
  EXPECT_GT(a[2], a[0]);  // far is blue
  DepthRampColor(1.0, a);
  DepthRampColor(7.0, b);
  EXPECT_EQ(a[0], b[0]);
  EXPECT_GT(a[0], a[2]);  // near is red
  DepthRampColor(std::numeric_limits<double>::quiet_NaN(), a);
  DepthRampColor(0.0, b);
  EXPECT_EQ(a[1], b[1]);
}

TEST(ColorMapTest, HeatIsMonotonicInLightness) {
  uint8_t prev[3];
  HeatColor(0.0, prev);
  for (int i = 1; i <= 100; ++i) {
    uint8_t c[3];
    HeatColor(i / 100.0, c);
    EXPECT_GE(Lightness(c), Lightness(prev)) << "t = " << i / 100.0;
    std::copy(c, c + 3, prev);
  }
}

TEST(ColorMapTest, ColorizeDepthNormalisesInverseDepth) {
  ImageF depth(4, 1, 1, 0.0f);
  depth.at(0, 0) = 1.0f;                                      // near end
  depth.at(1, 0) = 10.0f;                                     // far end
  depth.at(2, 0) = std::numeric_limits<float>::infinity();    // sky: black
  depth.at(3, 0) = -1.0f;                                     // invalid: black
  const Image8 rgb = ColorizeDepth(depth, 1.0, 10.0);
  uint8_t near[3], far[3];
  DepthRampColor(1.0, near);
  DepthRampColor(0.0, far);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(rgb.at(0, 0, c), near[c]);
    EXPECT_EQ(rgb.at(1, 0, c), far[c]);
    EXPECT_EQ(rgb.at(2, 0, c), 0);
    EXPECT_EQ(rgb.at(3, 0, c), 0);
  }
}

}  // namespace
}  // namespace casual3d::io
