#include "reconstruct/stitch/smooth_depth.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <gtest/gtest.h>

namespace casual3d::stitch {
namespace {

// A 10% step between two noisy planes: the noise falls, the step stays.
TEST(SmoothDepthTest, NoiseFallsAndStepsStay) {
  const int W = 64, H = 32;
  ImageF depth(W, H, 1, 0.0f);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> noise(-0.005f, 0.005f);
  auto truth = [](int x) { return x < 32 ? 2.0f : 2.2f; };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) depth.at(x, y) = truth(x) * (1.0f + noise(rng));
  depth.at(10, 10) = 0.0f;  // No depth: stays without.
  ImageF smoothed = depth;
  DepthSmoothOptions options;
  SmoothDepthAlongSurfaces(&smoothed, options, 2);
  double before = 0, after = 0;
  int n = 0;
  for (int y = 2; y < H - 2; ++y) {
    for (int x = 0; x < W; ++x) {
      if (x == 10 && y == 10) continue;
      const float t = truth(x);
      // Every pixel stays on its own side of the step, even beside it.
      ASSERT_NEAR(smoothed.at(x, y), t, 0.006f * t) << x << "," << y;
      before += std::pow(depth.at(x, y) / t - 1, 2);
      after += std::pow(smoothed.at(x, y) / t - 1, 2);
      ++n;
    }
  }
  EXPECT_LT(std::sqrt(after / n), 0.3 * std::sqrt(before / n));
  EXPECT_EQ(smoothed.at(10, 10), 0.0f);
}

// Each pass smooths further; threads do not change the result; depths
// that are not positive and finite stay as they are and count for nothing.
TEST(SmoothDepthTest, PassesThreadsAndInvalidDepths) {
  const int W = 48, H = 24;
  ImageF depth(W, H, 1, 0.0f);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> noise(-0.01f, 0.01f);
  for (float& d : depth.vector()) d = 3.0f * (1.0f + noise(rng));
  depth.at(5, 5) = std::nanf("");
  depth.at(6, 5) = -1.0f;
  depth.at(7, 5) = std::numeric_limits<float>::infinity();
  auto spread = [&](const ImageF& image) {
    double sq = 0;
    int n = 0;
    for (int y = 4; y < H - 4; ++y)
      for (int x = 10; x < W; ++x, ++n) sq += std::pow(image.at(x, y) / 3.0 - 1, 2);
    return std::sqrt(sq / n);
  };
  DepthSmoothOptions options;
  options.iterations = 1;
  ImageF one = depth;
  SmoothDepthAlongSurfaces(&one, options, 1);
  options.iterations = 2;
  ImageF two = depth, two_threads = depth;
  SmoothDepthAlongSurfaces(&two, options, 1);
  SmoothDepthAlongSurfaces(&two_threads, options, 3);
  EXPECT_LT(spread(two), 0.8 * spread(one));
  EXPECT_LT(spread(one), 0.5 * spread(depth));
  // Bit for bit (the NaN included, so not with ==).
  EXPECT_EQ(std::memcmp(two.vector().data(), two_threads.vector().data(),
                        two.vector().size() * sizeof(float)),
            0);
  EXPECT_TRUE(std::isnan(two.at(5, 5)));
  EXPECT_EQ(two.at(6, 5), -1.0f);
  EXPECT_TRUE(std::isinf(two.at(7, 5)));
  EXPECT_TRUE(std::isfinite(two.at(8, 5)) && std::abs(two.at(8, 5) - 3.0f) < 0.03f);
}

TEST(SmoothDepthTest, ColumnsWrapAndRadiusZeroKeepsTheDepth) {
  const int W = 16, H = 8;
  ImageF depth(W, H, 1, 1.0f);
  for (int y = 0; y < H; ++y) depth.at(0, y) = 1.02f;
  ImageF wrapped = depth;
  DepthSmoothOptions options;
  options.radius = 1;
  options.iterations = 1;
  SmoothDepthAlongSurfaces(&wrapped, options, 1);
  // Column W-1 sees column 0 across the seam, as column 1 does.
  EXPECT_GT(wrapped.at(W - 1, 4), 1.001f);
  EXPECT_NEAR(wrapped.at(W - 1, 4), wrapped.at(1, 4), 1e-6f);
  options.radius = 0;
  ImageF same = depth;
  SmoothDepthAlongSurfaces(&same, options, 1);
  EXPECT_EQ(same.vector(), depth.vector());
}

TEST(SmoothDepthTest, OptionsAreChecked) {
  DepthSmoothOptions options;
  EXPECT_TRUE(options.Check().ok());
  options.tolerance = 0;
  EXPECT_FALSE(options.Check().ok());
  ImageF depth(4, 4, 1, 1.0f);
  EXPECT_THROW(SmoothDepthAlongSurfaces(&depth, options), std::invalid_argument);
  options = DepthSmoothOptions();
  options.radius = 9;
  EXPECT_FALSE(options.Check().ok());
}

}  // namespace
}  // namespace casual3d::stitch
