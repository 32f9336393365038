#include "reconstruct/warp/warp.h"

#include <cmath>

#include <gtest/gtest.h>

#include "reconstruct/warp/test_scene.h"

namespace casual3d::warp {
namespace {

using testing::ForwardPose;
using testing::MakeCamera;

void MakeScene(const geometry::Camera& cam, const geometry::Pose& pose, double plane_z,
               double near_z, ImageF* depth, Image8* rgb) {
  testing::SquareScene scene;
  scene.plane_z = plane_z;
  scene.near_z = near_z;
  testing::RenderSquareScene(scene, cam, pose, depth, rgb);
}

TEST(WarpTest, CentredViewReproducesRadialDepthAndColor) {
  const geometry::Camera cam = MakeCamera(200, 150, 60.0);
  const geometry::Pose pose = ForwardPose(Eigen::Vector3d::Zero());
  ImageF depth;
  Image8 rgb;
  MakeScene(cam, pose, 4.0, 1.0, &depth, &rgb);
  WarpOptions options;
  options.pano_width = 1024;
  options.pano_height = 512;
  PanoramaFrame frame;  // Identity: world = panorama frame.
  SourceView view{&rgb, &depth, cam, pose};
  const WarpedView warped = WarpView(view, frame, options);

  // Straight ahead: the near square at 1 m, red channel 250.
  int cx, cy;
  ASSERT_TRUE(warped.front.ToCrop(512, 256, 1024, &cx, &cy));
  EXPECT_NEAR(warped.front.depth_m.at(cx, cy), 1.0, 1e-3);
  EXPECT_EQ(warped.front.rgb.at(cx, cy, 0), 250);
  // 20 degrees to the right: the background plane at 4 / cos(20 deg) along the ray.
  const int x20 = static_cast<int>(512 + 20.0 / 360.0 * 1024);
  ASSERT_TRUE(warped.front.ToCrop(x20, 256, 1024, &cx, &cy));
  const double lon = ((x20 + 0.5) / 1024 - 0.5) * 2 * kPi;
  EXPECT_NEAR(warped.front.depth_m.at(cx, cy), 4.0 / std::cos(lon), 4e-3);
  EXPECT_EQ(warped.front.rgb.at(cx, cy, 0), 10);
  EXPECT_LT(warped.front.stretch.at(cx, cy), 0.01);
  // Outside the field of view: nothing.
  EXPECT_FALSE(warped.front.ToCrop(0, 256, 1024, &cx, &cy) && warped.front.depth_m.at(cx, cy) > 0);
}

void CheckStretchedTriangles(double min_edge_depth_ratio);

TEST(WarpTest, StretchedTrianglesLoseToBackgroundAndBackWarpSeesBehind) {
  CheckStretchedTriangles(0.0);  // Every triangle drawn: rubber sheets reach the strip.
}

TEST(WarpTest, TrianglesAcrossDepthEdgesAreNotDrawn) {
  CheckStretchedTriangles(WarpOptions().min_edge_depth_ratio);
}

void CheckStretchedTriangles(double min_edge_depth_ratio) {
  // Seen from a camera 0.3 m to the right of the centre, the near square's
  // left edge produces stretched triangles that, from the centre, would cover
  // background. The front warp must prefer the unstretched background there,
  // and the back warp must show the background behind the square's middle
  // wherever the source saw it (it never sees behind the middle: there the
  // back warp keeps the square).
  const geometry::Camera cam = MakeCamera(400, 300, 70.0);
  const geometry::Pose pose = ForwardPose(Eigen::Vector3d(0.3, 0, 0));
  ImageF depth;
  Image8 rgb;
  MakeScene(cam, pose, 4.0, 1.0, &depth, &rgb);
  WarpOptions options;
  options.pano_width = 2048;
  options.pano_height = 1024;
  options.min_edge_depth_ratio = min_edge_depth_ratio;
  SourceView view{&rgb, &depth, cam, pose};
  const WarpedView warped = WarpView(view, PanoramaFrame(), options);

  // Pixel column of a longitude, row of a latitude (degrees).
  auto col = [](double lon_deg) { return static_cast<int>((lon_deg / 360.0 + 0.5) * 2048); };
  auto row = [](double lat_deg) { return static_cast<int>((0.5 - lat_deg / 180.0) * 1024); };
  int right_stretched = 0, right_covered = 0, right_back_behind = 0;
  int left_stretched = 0, left_covered = 0;
  for (int y = row(8); y <= row(-8); ++y) {
    // Right of the square's centre, 5..15 degrees: from the centre the square;
    // the camera saw it unstretched and also saw the background behind it.
    for (int x = col(5); x <= col(15); ++x) {
      int cx, cy, bx, by;
      if (!warped.front.ToCrop(x, y, 2048, &cx, &cy) || warped.front.depth_m.at(cx, cy) <= 0)
        continue;
      ++right_covered;
      const double lon = (x + 0.5 - 1024) / 2048.0 * 2 * kPi;
      const double lat = (512 - y - 0.5) / 1024.0 * kPi;
      EXPECT_NEAR(warped.front.depth_m.at(cx, cy), 1.0 / (std::cos(lon) * std::cos(lat)), 0.01);
      if (warped.front.stretch.at(cx, cy) > 0.5) ++right_stretched;
      if (warped.back.ToCrop(x, y, 2048, &bx, &by) && warped.back.depth_m.at(bx, by) > 3.5f)
        ++right_back_behind;
    }
    // Left of the square's left edge, 18..26 degrees: background from the
    // centre, but occluded from the camera: only stretched triangles reach it.
    for (int x = col(-26); x <= col(-18); ++x) {
      int cx, cy;
      if (!warped.front.ToCrop(x, y, 2048, &cx, &cy) || warped.front.depth_m.at(cx, cy) <= 0)
        continue;
      ++left_covered;
      if (warped.front.stretch.at(cx, cy) > 0.5) ++left_stretched;
    }
  }
  const int rows = row(-8) - row(8) + 1;
  EXPECT_EQ(right_covered, rows * (col(15) - col(5) + 1));
  EXPECT_EQ(right_stretched, 0);
  EXPECT_GT(right_back_behind, right_covered * 9 / 10);
  if (options.min_edge_depth_ratio == 0) {
    EXPECT_GT(left_covered, rows * 10);
    EXPECT_EQ(left_stretched, left_covered);
  } else {
    // Triangles across the square's edge (depths 1 and 4) are not drawn:
    // nothing of the photo reaches the strip it could not see.
    EXPECT_EQ(left_covered, 0);
  }
}

TEST(WarpTest, SeamIsContinuous) {
  // A camera looking backwards (+Z) straddles the +-180 degree seam.
  const geometry::Camera cam = MakeCamera(200, 150, 60.0);
  Eigen::Matrix3d R;
  R << -1, 0, 0, 0, -1, 0, 0, 0, 1;  // Camera z = +Z, x = -X.
  const geometry::Pose pose = geometry::Pose::FromCenter(R, Eigen::Vector3d::Zero());
  ImageF depth(cam.width, cam.height, 1, 3.0f);
  Image8 rgb(cam.width, cam.height, 3, 128);
  WarpOptions options;
  options.pano_width = 1024;
  options.pano_height = 512;
  SourceView view{&rgb, &depth, cam, pose};
  const WarpedView warped = WarpView(view, PanoramaFrame(), options);
  // Every column within +-25 degrees of the seam on the horizon is covered.
  for (int dx = -70; dx < 70; ++dx) {
    const int x = WrapColumn(dx, 1024);
    int cx, cy;
    ASSERT_TRUE(warped.front.ToCrop(x, 256, 1024, &cx, &cy)) << "column " << x;
    EXPECT_GT(warped.front.depth_m.at(cx, cy), 2.9f) << "column " << x;
  }
}

TEST(WarpTest, RejectsBadOptions) {
  WarpOptions options;
  options.pano_width = 1000;
  options.pano_height = 400;
  EXPECT_FALSE(options.Check().ok());
  options = WarpOptions();
  options.tau_stretch_deg = 0;
  EXPECT_FALSE(options.Check().ok());
  EXPECT_TRUE(WarpOptions().Check().ok());
}

}  // namespace
}  // namespace casual3d::warp
