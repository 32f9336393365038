#include "reconstruct/pipeline/coverage.h"

#include <gtest/gtest.h>

#include <cmath>

#include "reconstruct/warp/test_scene.h"

namespace casual3d::pipeline {
namespace {

using warp::testing::ForwardPose;
using warp::testing::MakeCamera;

constexpr int kW = 720, kH = 360;  // Half a degree per pixel.

// Pixel of the panorama at (lon, lat) in degrees.
void PixelAt(double lon_deg, double lat_deg, int* x, int* y) {
  *x = static_cast<int>(std::floor((lon_deg / 360.0 + 0.5) * kW));
  *y = static_cast<int>(std::floor((0.5 - lat_deg / 180.0) * kH));
}

TwoLayerPanorama FullFront(float depth_m) {
  TwoLayerPanorama pano(kW, kH);
  LayerData& f = pano.layer(kFront);
  for (size_t i = 0; i < f.present.size(); ++i) {
    f.present[i] = 1;
    f.depth_m[i] = depth_m;
  }
  return pano;
}

bool Inside(const Image8& mask, double lon_deg, double lat_deg) {
  int x, y;
  PixelAt(lon_deg, lat_deg, &x, &y);
  return mask.at(x, y) != 0;
}

TEST(CoverageTest, FieldOfViewOfACentredCameraIsItsFrustum) {
  const TwoLayerPanorama pano = FullFront(2.0f);
  const std::vector<CoverageView> views = {{MakeCamera(400, 300, 90.0), ForwardPose({0, 0, 0})}};
  const Image8 fov = FieldOfViewMask(pano, kFront, views);
  EXPECT_TRUE(Inside(fov, 0, 0));
  EXPECT_TRUE(Inside(fov, 43, 0));
  EXPECT_FALSE(Inside(fov, 47, 0));
  EXPECT_TRUE(Inside(fov, 0, 35));
  EXPECT_FALSE(Inside(fov, 0, 38.5));
  EXPECT_FALSE(Inside(fov, 180, 0));
  const CoverageStats stats = MeasureHoles(pano, kFront, fov);
  // Solid angle of a frustum with half-angles a, b: 4 asin(sin a sin b);
  // here a = 45 degrees and tan b = 0.75.
  const double expected = 4.0 * std::asin(std::sin(kPi / 4) * std::sin(std::atan(0.75)));
  EXPECT_NEAR(stats.fov_steradians, expected, 0.01 * expected);
  EXPECT_DOUBLE_EQ(stats.covered_fraction, 1.0);
  EXPECT_EQ(stats.num_holes, 0);
  EXPECT_EQ(stats.largest_hole_fraction, 0.0);
}

TEST(CoverageTest, FieldOfViewFollowsParallaxAtTheLayersDepth) {
  // A camera 0.5 m right of the centre, looking forward with 45 degrees of
  // horizontal field of view. At 1 m from the centre it sees longitudes 5 to
  // 50 degrees (sin(lon) - 0.5 = +-tan(22.5 deg) cos(lon)); at 100 m about
  // -22 to 23 degrees.
  const std::vector<CoverageView> views = {{MakeCamera(400, 300, 45.0), ForwardPose({0.5, 0, 0})}};
  const Image8 near_mask = FieldOfViewMask(FullFront(1.0f), kFront, views);
  EXPECT_TRUE(Inside(near_mask, 26.6, 0));
  EXPECT_TRUE(Inside(near_mask, 6, 0));
  EXPECT_FALSE(Inside(near_mask, 3, 0));
  EXPECT_TRUE(Inside(near_mask, 48, 0));
  EXPECT_FALSE(Inside(near_mask, 52, 0));
  const Image8 far_mask = FieldOfViewMask(FullFront(100.0f), kFront, views);
  EXPECT_TRUE(Inside(far_mask, -20, 0));
  EXPECT_FALSE(Inside(far_mask, 26.6, 0));
  // Pixels without a node take the depth of the nearest node: a layer with
  // nodes at 1 m at longitudes 10 to 20 degrees only gives the 1 m footprint.
  TwoLayerPanorama patch(kW, kH);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const double lon = (x + 0.5) / kW * 360.0 - 180.0;
      if (lon < 10 || lon > 20) continue;
      patch.layer(kFront).present[patch.index(x, y)] = 1;
      patch.layer(kFront).depth_m[patch.index(x, y)] = 1.0f;
    }
  }
  const Image8 patch_mask = FieldOfViewMask(patch, kFront, views, 100.0);
  EXPECT_TRUE(Inside(patch_mask, 48, 0));
  EXPECT_FALSE(Inside(patch_mask, -10, 0));
  EXPECT_FALSE(Inside(patch_mask, 3, 10));
  // An empty layer uses the reference depth.
  TwoLayerPanorama empty(kW, kH);
  double used = 0;
  const Image8 ref_mask = FieldOfViewMask(empty, kFront, views, 1.0, 1, &used);
  EXPECT_EQ(used, 1.0);
  EXPECT_TRUE(Inside(ref_mask, 26.6, 0));
  EXPECT_FALSE(Inside(ref_mask, 3, 0));
}

TEST(CoverageTest, HolesAreComponentsMeasuredBySolidAngle) {
  TwoLayerPanorama pano = FullFront(2.0f);
  const std::vector<CoverageView> views = {{MakeCamera(400, 300, 90.0), ForwardPose({0, 0, 0})}};
  const Image8 fov = FieldOfViewMask(pano, kFront, views);
  LayerData& f = pano.layer(kFront);
  // An interior 10 x 10 hole around the forward direction...
  int cx, cy;
  PixelAt(0, 0, &cx, &cy);
  for (int y = cy - 5; y < cy + 5; ++y)
    for (int x = cx - 5; x < cx + 5; ++x) f.present[pano.index(x, y)] = 0;
  // ... a 3 x 4 one ...
  PixelAt(-20, 10, &cx, &cy);
  for (int y = cy; y < cy + 4; ++y)
    for (int x = cx; x < cx + 3; ++x) f.present[pano.index(x, y)] = 0;
  // ... and a strip along the right edge of the field of view (and beyond).
  PixelAt(40, 0, &cx, &cy);
  for (int y = cy - 20; y < cy + 20; ++y)
    for (int x = cx; x < cx + 30; ++x) f.present[pano.index(x, y)] = 0;

  Image8 holes;
  const CoverageStats stats = MeasureHoles(pano, kFront, fov, &holes);
  EXPECT_EQ(stats.num_holes, 3);
  EXPECT_EQ(stats.num_interior_holes, 2);
  // The edge strip: columns 40.0 .. 45 degrees (10 inside), 40 rows.
  EXPECT_GE(stats.largest_hole_pixels, 9 * 40);
  EXPECT_LE(stats.largest_hole_pixels, 11 * 40);
  const double pixel_sr = (2 * kPi / kW) * (kPi / kH);  // At the equator.
  EXPECT_NEAR(stats.largest_interior_hole_fraction, 100 * pixel_sr / stats.fov_steradians,
              0.01 * 100 * pixel_sr / stats.fov_steradians);
  EXPECT_EQ(stats.hole_pixels, 100 + 12 + stats.largest_hole_pixels);
  EXPECT_NEAR(stats.covered_fraction,
              1.0 - (112 + stats.largest_hole_pixels) * pixel_sr / stats.fov_steradians, 2e-3);
  PixelAt(0, 0, &cx, &cy);
  EXPECT_EQ(holes.at(cx, cy), 255);
  EXPECT_EQ(holes.at(cx + 6, cy), 0);
}

TEST(CoverageTest, HolesWrapAroundTheSeam) {
  TwoLayerPanorama pano = FullFront(2.0f);
  // A camera looking backwards (+Z): its view straddles the +-180 degree seam.
  Eigen::Matrix3d R;
  R << -1, 0, 0, 0, -1, 0, 0, 0, 1;
  const std::vector<CoverageView> views = {
      {MakeCamera(400, 300, 60.0), geometry::Pose::FromCenter(R, {0, 0, 0})}};
  const Image8 fov = FieldOfViewMask(pano, kFront, views);
  EXPECT_TRUE(Inside(fov, 179.9, 0));
  EXPECT_TRUE(Inside(fov, -179.9, 0));
  LayerData& f = pano.layer(kFront);
  for (int y = kH / 2 - 4; y < kH / 2 + 4; ++y)
    for (int x : {0, 1, 2, kW - 3, kW - 2, kW - 1}) f.present[pano.index(x, y)] = 0;
  const CoverageStats stats = MeasureHoles(pano, kFront, fov);
  EXPECT_EQ(stats.num_holes, 1);
  EXPECT_EQ(stats.num_interior_holes, 1);
  EXPECT_EQ(stats.hole_pixels, 48);
}

TEST(CoverageTest, FootprintIsTheUnionOfTheFrontWarpsAcrossTheSeam) {
  // Two cropped warps: one straddling the +-180 degree seam, one with a gap.
  std::vector<warp::WarpedView> warps(2);
  warp::WarpedLayer& a = warps[0].front;
  a.x0 = kW - 4;
  a.y0 = 10;
  a.depth_m = ImageF(8, 3, 1, 2.0f);
  warp::WarpedLayer& b = warps[1].front;
  b.x0 = 100;
  b.y0 = 200;
  b.depth_m = ImageF(5, 5, 1, 3.0f);
  b.depth_m.at(2, 2) = 0.0f;  // Nothing landed here.
  const Image8 mask = FootprintMask(warps, kW, kH);
  int inside = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) inside += mask.at(x, y) != 0;
  EXPECT_EQ(inside, 24 + 24);
  EXPECT_EQ(mask.at(kW - 4, 10), 255);
  EXPECT_EQ(mask.at(3, 12), 255);
  EXPECT_EQ(mask.at(4, 12), 0);
  EXPECT_EQ(mask.at(102, 202), 0);
  EXPECT_EQ(mask.at(104, 204), 255);
  // Holes of a layer inside the footprint: the layer has nodes on warp a only.
  TwoLayerPanorama pano(kW, kH);
  for (int y = 10; y < 13; ++y)
    for (int x : {kW - 4, kW - 3, kW - 2, kW - 1, 0, 1, 2, 3}) pano.layer(kFront).present[pano.index(x, y)] = 1;
  const CoverageStats stats = MeasureHoles(pano, kFront, mask);
  EXPECT_EQ(stats.num_holes, 1);
  EXPECT_EQ(stats.hole_pixels, 24);
}

TEST(CoverageTest, GapsInsideTheMaskCloseRingByRingFromTheirRims) {
  constexpr int W = 16, H = 8;
  Image8 rgb(W, H, 3, 0), mask(W, H, 1, 0);
  ImageF depth(W, H, 1, 0.0f);
  Image<int16_t> label(W, H, 1, -1);
  auto set = [&](int x, int y, float d, uint8_t grey, int16_t l) {
    depth.at(x, y) = d;
    for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = grey;
    label.at(x, y) = l;
  };
  // Row 2..5: a near object (1 m, grey 200) in columns 0..3, a gap in 4..7,
  // a far wall (10 m, grey 60 or 80 in alternate rows) in 8..12; columns
  // 13..15 are a gap that wraps around to the near object.
  for (int y = 2; y <= 5; ++y) {
    for (int x = 0; x <= 3; ++x) set(x, y, 1.0f, 200, 1);
    for (int x = 8; x <= 12; ++x) set(x, y, 10.0f, y % 2 ? 60 : 80, 2);
  }
  for (int y = 2; y <= 5; ++y)
    for (int x = 0; x < W; ++x) mask.at(x, y) = 255;
  mask.at(13, 5) = 0;  // Outside the field of view: stays empty.
  const int64_t filled = FillGapsInside(mask, &rgb, &depth, &label);
  EXPECT_EQ(filled, 4 * 4 + 3 * 4 - 1);
  for (int y = 2; y <= 5; ++y) {
    // The gap between the object and the wall closes from both sides, one
    // ring a step: columns 4 and 5 continue the object, 6 and 7 the wall.
    for (int x = 4; x <= 7; ++x) {
      const bool wall = x >= 6;
      EXPECT_FLOAT_EQ(depth.at(x, y), wall ? 10.0f : 1.0f) << x << "," << y;
      EXPECT_EQ(label.at(x, y), wall ? 2 : 1);
    }
    // Columns 13..15 between the wall (column 12) and the object (column 0,
    // across the seam): 13 from the wall, 15 from the object, and 14, which
    // both rings reach at once, from the farther of the two.
    if (y < 5) {
      EXPECT_FLOAT_EQ(depth.at(13, y), 10.0f) << y;
    }
    EXPECT_FLOAT_EQ(depth.at(14, y), 10.0f) << y;
    EXPECT_FLOAT_EQ(depth.at(15, y), 1.0f) << y;
  }
  // Colour: the wall's texture mirrored through the rim (rows alternate 60
  // and 80): (7, 3) mirrors (9, 3), (6, 2) mirrors (10, 2); the object's
  // side is uniform.
  EXPECT_EQ(rgb.at(7, 3, 0), 60);
  EXPECT_EQ(rgb.at(6, 2, 0), 80);
  EXPECT_EQ(rgb.at(6, 3, 0), 60);
  EXPECT_EQ(rgb.at(5, 3, 0), 200);
  // (14, 2): from the wall two rings away (column 12); its mirror, column 10,
  // is wall: 80.
  EXPECT_EQ(rgb.at(14, 2, 0), 80);
  EXPECT_FLOAT_EQ(depth.at(13, 5), 0.0f);
  // Rows outside the mask stay empty.
  for (int x = 0; x < W; ++x) EXPECT_FLOAT_EQ(depth.at(x, 0), 0.0f);
  // Nothing to fill from: an empty layer stays empty.
  ImageF empty(W, H, 1, 0.0f);
  Image8 empty_rgb(W, H, 3, 0);
  EXPECT_EQ(FillGapsInside(mask, &empty_rgb, &empty, nullptr), 0);
}

TEST(CoverageTest, RejectsAMaskOfTheWrongSize) {
  const TwoLayerPanorama pano = FullFront(2.0f);
  EXPECT_THROW(MeasureHoles(pano, kFront, Image8(10, 5, 1, 0)), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::pipeline
