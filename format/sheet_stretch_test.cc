#include "format/sheet_stretch.h"

#include <gtest/gtest.h>

#include <cmath>

namespace casual3d {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The point at `depth` along the ray of longitude `lon` and latitude `lat`.
void At(double lon, double lat, double depth, float out[3]) {
  out[0] = static_cast<float>(depth * std::cos(lat) * std::sin(lon));
  out[1] = static_cast<float>(depth * std::sin(lat));
  out[2] = static_cast<float>(-depth * std::cos(lat) * std::cos(lon));
}

TEST(SheetStretchTest, SeenFromTheCentreEveryTriangleHasStretchOne) {
  const double centre[3] = {0, 0, 0};
  const double px = 2 * kPi / 4096;
  float a[3], b[3], c[3];
  At(0.3, 0.1, 2.0, a);
  At(0.3 + px, 0.1, 7.0, b);  // Across a depth step.
  At(0.3, 0.1 + px, 2.1, c);
  EXPECT_NEAR(SheetStretch(a, b, c, centre), 1.0, 1e-3);
}

TEST(SheetStretchTest, ASurfaceSeenFromOffTheCentreBarelyStretches) {
  const double eye[3] = {0.05, 0.02, 0.0};
  const double px = 2 * kPi / 4096;
  float a[3], b[3], c[3];
  At(0.0, 0.0, 2.0, a);
  At(px, 0.0, 2.0, b);
  At(0.0, px, 2.0, c);
  const double s = SheetStretch(a, b, c, eye);
  EXPECT_GT(s, 0.95);
  EXPECT_LT(s, 1.1);
}

TEST(SheetStretchTest, ALinkAcrossADepthStepStretchesWithTheEyesOffset) {
  const double px = 2 * kPi / 4096;
  float a[3], b[3], c[3];
  At(0.0, 0.0, 1.0, a);  // A leaf ...
  At(px, 0.0, 4.0, b);   // ... linked to the wall behind it.
  At(0.0, px, 1.0, c);
  // Moving sideways by 0.05 moves the two depths apart by about
  // 0.05 * (1 / 1 - 1 / 4) = 0.0375 radians, 24 pixels' angle.
  const double eye[3] = {0.05, 0.0, 0.0};
  const double s = SheetStretch(a, b, c, eye);
  EXPECT_GT(s, 20.0);
  EXPECT_LT(s, 30.0);
  EXPECT_GT(s, kDefaultSheetStretch);
  // Moving towards it along its ray barely stretches it.
  const double forward[3] = {0.0, 0.0, -0.05};
  EXPECT_LT(SheetStretch(a, b, c, forward), 1.2);
}

TEST(SheetStretchTest, EdgeOnFromTheEyeIsZeroAndDegenerateFromTheCentreInfinite) {
  // Three points on one ray from the centre: degenerate seen from it.
  const float a[3] = {0, 0, -1}, b[3] = {0, 0, -2}, c[3] = {0, 0, -3};
  const double eye[3] = {0.1, 0.1, 0.0};
  EXPECT_TRUE(std::isinf(SheetStretch(a, b, c, eye)));
  // Three points on one ray from the eye.
  const float d[3] = {0.1f, 0.1f, -1}, e[3] = {0.1f, 0.1f, -2}, f[3] = {0.1f, 0.1f, -3};
  EXPECT_EQ(SheetStretch(d, e, f, eye), 0.0);
}

TEST(SheetStretchTest, GeneralisedEigenvalueMatchesTheQuadratic) {
  // Gu = [[4, 1], [1, 3]], Ge = [[2, 0], [0, 1]]: det(Gu - l Ge) =
  // 2 l^2 - 10 l + 11, roots (10 -+ sqrt(12)) / 4.
  const double gu[3] = {4, 1, 3}, ge[3] = {2, 0, 1};
  EXPECT_NEAR(SmallerGeneralisedEigenvalue(gu, ge), (10 - std::sqrt(12.0)) / 4, 1e-12);
  const double singular[3] = {1, 1, 1};
  EXPECT_EQ(SmallerGeneralisedEigenvalue(gu, singular), -1.0);
}

}  // namespace
}  // namespace casual3d
