#include "reconstruct/pipeline/view_volume.h"

#include <gtest/gtest.h>

#include <cmath>

namespace casual3d::pipeline {
namespace {

Image8 MaskOfColumns(int W, int H, int x0, int x1, int y0, int y1) {
  Image8 mask(W, H, 1, 0);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) mask.at(((x % W) + W) % W, y) = 255;
  return mask;
}

TEST(ContentExtent, FrontRegion) {
  // Columns 96..160 of 256 (longitudes -45 .. +45), rows 32..96 of 128.
  ViewHints h;
  ASSERT_TRUE(ContentExtent(MaskOfColumns(256, 128, 96, 160, 32, 96), &h));
  EXPECT_DOUBLE_EQ(h.content_yaw_min_deg, -45.0);
  EXPECT_DOUBLE_EQ(h.content_yaw_max_deg, 45.0);
  EXPECT_DOUBLE_EQ(h.content_pitch_max_deg, 45.0);
  EXPECT_DOUBLE_EQ(h.content_pitch_min_deg, -45.0);
  EXPECT_TRUE(h.Validate().ok());
}

TEST(ContentExtent, AcrossTheSeamIsOneInterval) {
  // Columns 240..271 wrap: longitudes 157.5 .. 202.5, written with the
  // middle in [-180, 180): -202.5 .. -157.5.
  ViewHints h;
  ASSERT_TRUE(ContentExtent(MaskOfColumns(256, 128, 240, 272, 0, 128), &h));
  EXPECT_DOUBLE_EQ(h.content_yaw_min_deg, -202.5);
  EXPECT_DOUBLE_EQ(h.content_yaw_max_deg, -157.5);
  EXPECT_DOUBLE_EQ(h.content_pitch_min_deg, -90.0);
  EXPECT_DOUBLE_EQ(h.content_pitch_max_deg, 90.0);
  EXPECT_TRUE(h.Validate().ok());
}

TEST(ContentExtent, EmptyCornerLeavesTheBox) {
  // Columns 96..160 (longitudes -45 .. 45), rows 32..96 (latitudes 45 ..
  // -45), without its top-left corner (columns 96..112, rows 32..48): sky
  // above trees that no photo saw. The box loses the corner's rows or its
  // columns, whichever keeps more content, so that at most 0.5% of it is
  // empty.
  Image8 mask = MaskOfColumns(256, 128, 96, 160, 32, 96);
  for (int y = 32; y < 48; ++y)
    for (int x = 96; x < 112; ++x) mask.at(x, y) = 0;
  ViewHints h;
  ASSERT_TRUE(ContentExtent(mask, &h));
  const bool lost_top = h.content_pitch_max_deg <= 90.0 - 180.0 * 48 / 128 + 1e-9;
  const bool lost_left = h.content_yaw_min_deg >= -180.0 + 360.0 * 112 / 256 - 1e-9;
  EXPECT_TRUE(lost_top || lost_left) << h.content_yaw_min_deg << " " << h.content_pitch_max_deg;
  // Only that: the other sides stay.
  EXPECT_DOUBLE_EQ(h.content_yaw_max_deg, 45.0);
  EXPECT_DOUBLE_EQ(h.content_pitch_min_deg, -45.0);
  // The same across the seam: columns 240..303 wrap, the corner 240..255.
  Image8 seam = MaskOfColumns(256, 128, 240, 304, 32, 96);
  for (int y = 32; y < 48; ++y)
    for (int x = 240; x < 256; ++x) seam.at(x, y) = 0;
  ViewHints s;
  ASSERT_TRUE(ContentExtent(seam, &s));
  EXPECT_NEAR(s.content_yaw_max_deg - (-180.0 + 360.0 * 48 / 256), 0.0, 1e-9);
  EXPECT_LT(s.content_yaw_max_deg - s.content_yaw_min_deg, 90.0 + 1e-9);
  EXPECT_TRUE(s.content_yaw_min_deg < -180.0 || s.content_pitch_max_deg < 45.0 - 1e-9);
  EXPECT_TRUE(s.Validate().ok());
}

TEST(ContentExtent, FullCircleAndEmpty) {
  ViewHints h;
  ASSERT_TRUE(ContentExtent(MaskOfColumns(64, 32, 0, 64, 10, 20), &h));
  EXPECT_DOUBLE_EQ(h.content_yaw_max_deg - h.content_yaw_min_deg, 360.0);
  EXPECT_FALSE(ContentExtent(Image8(64, 32, 1, 0), &h));
}

CoverageView CameraAt(double x, double yaw_deg) {
  CoverageView v;
  v.camera.model = geometry::CameraModelId::kPinhole;
  v.camera.width = 640;
  v.camera.height = 480;
  v.camera.params = {400, 400, 320, 240};  // Short side: 2 atan(240 / 400) = 61.9 deg.
  // Camera looking along panorama direction yaw (pitch 0): camera +Z = that
  // direction, +X right, +Y down.
  const double a = yaw_deg * kPi / 180.0;
  const Eigen::Vector3d forward(std::sin(a), 0, -std::cos(a));
  const Eigen::Vector3d right(std::cos(a), 0, std::sin(a));
  const Eigen::Vector3d down(0, -1, 0);
  Eigen::Matrix3d Rwc;
  Rwc.row(0) = right;
  Rwc.row(1) = down;
  Rwc.row(2) = forward;
  v.pose = geometry::Pose::FromCenter(Rwc, Eigen::Vector3d(x, 0, 0));
  return v;
}

TwoLayerPanorama FrontAt(int W, int H, float depth) {
  TwoLayerPanorama pano(W, H);
  for (size_t i = 0; i < pano.layer(kFront).present.size(); ++i) {
    pano.layer(kFront).present[i] = 1;
    pano.layer(kFront).depth_m[i] = depth;
  }
  return pano;
}

TEST(ComputeViewHints, DirectionFieldOfViewAndVolume) {
  const int W = 256, H = 128;
  const TwoLayerPanorama pano = FrontAt(W, H, 2.0f);
  // Content over longitudes -90 .. 90, latitudes -45 .. 45.
  const Image8 fov = MaskOfColumns(W, H, 64, 192, 32, 96);
  std::vector<CoverageView> views = {CameraAt(-0.05, -20), CameraAt(0.05, 20), CameraAt(0.0, 30)};
  const ViewHints h = ComputeViewHints(pano, fov, views, PanoramaFrame(), /*metric=*/true);
  EXPECT_TRUE(h.Validate().ok());
  EXPECT_TRUE(h.metric);
  EXPECT_NEAR(h.yaw_deg, 10.0, 0.5);  // Mean of the axes' directions.
  EXPECT_NEAR(h.pitch_deg, 0.0, 1e-9);
  EXPECT_NEAR(h.fov_deg, 2 * std::atan(240.0 / 400.0) * 180 / kPi, 1e-6);
  // Cameras 0.05 from the centre; the near depth is 2: radius within [0.04, 0.12].
  EXPECT_NEAR(h.volume_radius, 0.05, 1e-9);

  // Cameras far apart: the radius is capped at 0.06 of the near depth.
  views = {CameraAt(-1.0, 0), CameraAt(1.0, 0)};
  EXPECT_NEAR(ComputeViewHints(pano, fov, views, PanoramaFrame(), false).volume_radius, 0.12, 1e-6);
  // Cameras at one point (a pure rotation): the smallest radius.
  views = {CameraAt(0, -10), CameraAt(0, 10)};
  EXPECT_NEAR(ComputeViewHints(pano, fov, views, PanoramaFrame(), false).volume_radius, 0.04, 1e-6);
}

TEST(ComputeViewHints, NarrowContentNarrowsAndCentresTheView) {
  const int W = 256, H = 128;
  const TwoLayerPanorama pano = FrontAt(W, H, 3.0f);
  // Content only 22.5 deg tall (rows 56..72) and 45 wide (columns 112..144).
  const Image8 fov = MaskOfColumns(W, H, 112, 144, 56, 72);
  const std::vector<CoverageView> views = {CameraAt(0, 40)};
  const ViewHints h = ComputeViewHints(pano, fov, views, PanoramaFrame(), false);
  EXPECT_LE(h.fov_deg, 0.95 * 22.5 + 1e-9);
  // The view cannot fit the camera's direction (40 deg) inside 45 deg of
  // content: it is moved inside.
  EXPECT_LT(h.yaw_deg, 22.5);
  EXPECT_GT(h.yaw_deg, -22.5);
}

TEST(ViewVolumeOptions, Check) {
  ViewVolumeOptions o;
  EXPECT_TRUE(o.Check().ok());
  o.max_radius_over_near = 0.01;
  EXPECT_FALSE(o.Check().ok());
  o = ViewVolumeOptions();
  o.frame_aspect = 10;
  EXPECT_FALSE(o.Check().ok());
}

}  // namespace
}  // namespace casual3d::pipeline
