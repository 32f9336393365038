#include "format/equirect.h"

#include <gtest/gtest.h>

#include <cmath>

namespace casual3d {
namespace {

void ExpectDirectionNear(const Vec3d& d, double x, double y, double z, double tol = 1e-12) {
  EXPECT_NEAR(d.x, x, tol);
  EXPECT_NEAR(d.y, y, tol);
  EXPECT_NEAR(d.z, z, tol);
}

// The convention written in spec/projection.md, point by point.
TEST(EquirectTest, CardinalDirections) {
  ExpectDirectionNear(LonLatToDirection(0, 0), 0, 0, -1);           // forward is -Z
  ExpectDirectionNear(LonLatToDirection(kPi / 2, 0), 1, 0, 0);      // right is +X
  ExpectDirectionNear(LonLatToDirection(-kPi / 2, 0), -1, 0, 0);    // left is -X
  ExpectDirectionNear(LonLatToDirection(-kPi, 0), 0, 0, 1);         // behind is +Z
  ExpectDirectionNear(LonLatToDirection(0.3, kPi / 2), 0, 1, 0);    // zenith is +Y
  ExpectDirectionNear(LonLatToDirection(0.3, -kPi / 2), 0, -1, 0);  // nadir is -Y
}

TEST(EquirectTest, PixelGridLandmarks) {
  const int w = 4096, h = 2048;
  // The image centre looks forward; the left edge is behind; the top edge is
  // the zenith; a quarter of the width is the left (-X) direction.
  ExpectDirectionNear(EquirectPixelToDirection(w / 2.0, h / 2.0, w, h), 0, 0, -1);
  ExpectDirectionNear(EquirectPixelToDirection(0.0, h / 2.0, w, h), 0, 0, 1);
  ExpectDirectionNear(EquirectPixelToDirection(w * 0.25, h / 2.0, w, h), -1, 0, 0);
  ExpectDirectionNear(EquirectPixelToDirection(w * 0.75, h / 2.0, w, h), 1, 0, 0);
  ExpectDirectionNear(EquirectPixelToDirection(123.0, 0.0, w, h), 0, 1, 0);
  ExpectDirectionNear(EquirectPixelToDirection(123.0, h, w, h), 0, -1, 0);
  // Pixel (0, 0)'s centre is at (0.5, 0.5): half a pixel from the zenith and
  // half a pixel east of the seam.
  double lon, lat;
  DirectionToLonLat(EquirectPixelToDirection(0.5, 0.5, w, h), &lon, &lat);
  EXPECT_NEAR(lon, -kPi + kPi / w, 1e-12);
  EXPECT_NEAR(lat, kPi / 2 - kPi / (2.0 * h), 1e-12);
}

TEST(EquirectTest, PixelDirectionRoundTripOverAllPixelCentres) {
  const int w = 360, h = 180;
  double max_error = 0.0;
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      const double u = i + 0.5, v = j + 0.5;
      const Vec3d d = EquirectPixelToDirection(u, v, w, h);
      EXPECT_NEAR(d.x * d.x + d.y * d.y + d.z * d.z, 1.0, 1e-12);
      double u2, v2;
      DirectionToEquirectPixel(d, w, h, &u2, &v2);
      max_error = std::max(max_error, std::max(std::abs(u2 - u), std::abs(v2 - v)));
    }
  }
  EXPECT_LT(max_error, 1e-9);
}

TEST(EquirectTest, DirectionNeedNotBeUnitAndZeroIsSafe) {
  double lon, lat;
  DirectionToLonLat({0, 0, -5}, &lon, &lat);
  EXPECT_NEAR(lon, 0, 1e-15);
  EXPECT_NEAR(lat, 0, 1e-15);
  DirectionToLonLat({3, 3 * std::sqrt(2.0), -3}, &lon, &lat);
  EXPECT_NEAR(lon, kPi / 4, 1e-12);
  EXPECT_NEAR(lat, kPi / 4, 1e-12);
  // The zero vector gives finite angles (no NaN reaches pixel arithmetic).
  DirectionToLonLat({0, 0, 0}, &lon, &lat);
  EXPECT_TRUE(std::isfinite(lon));
  EXPECT_EQ(lat, 0.0);
}

TEST(EquirectTest, SeamAndColumnWrap) {
  const int w = 100, h = 50;
  // Directly behind (+Z) maps to the seam: lon = +pi gives u = width and
  // lon = -pi gives u = 0; both describe the same column boundary.
  double u, v;
  DirectionToEquirectPixel({0, 0, 1}, w, h, &u, &v);
  EXPECT_TRUE(std::abs(u - w) < 1e-9 || std::abs(u) < 1e-9) << u;
  EXPECT_NEAR(v, h / 2.0, 1e-9);
  // Longitude grows towards the right (+X), so behind-and-slightly-right
  // (lon just below +pi) is at the right edge, behind-and-slightly-left
  // (lon just above -pi) at the left edge.
  DirectionToEquirectPixel({1e-3, 0, 1}, w, h, &u, &v);
  EXPECT_NEAR(u, w - 1e-3 / (2 * kPi) * w, 1e-6);
  DirectionToEquirectPixel({-1e-3, 0, 1}, w, h, &u, &v);
  EXPECT_NEAR(u, 1e-3 / (2 * kPi) * w, 1e-6);
  EXPECT_EQ(WrapColumn(-1, w), w - 1);
  EXPECT_EQ(WrapColumn(w, w), 0);
  EXPECT_EQ(WrapColumn(-w - 3, w), w - 3);
  EXPECT_EQ(WrapColumn(2 * w + 7, w), 7);
  EXPECT_EQ(WrapColumn(42, w), 42);
}

TEST(EquirectTest, PanoramaFrameDefaultIsIdentity) {
  const PanoramaFrame frame;
  for (int i = 0; i < 3; ++i) EXPECT_EQ(frame.centre[i], 0.0);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(frame.rotation[r * 3 + c], r == c ? 1.0 : 0.0);
  }
}

}  // namespace
}  // namespace casual3d
