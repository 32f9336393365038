#include "reconstruct/depth/depth_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace casual3d::depth {
namespace {

// Three cameras side by side (0.1 m apart along x) looking down +z at a
// fronto-parallel wall 5 m away: the true depth is 5 m everywhere.
struct Rig {
  std::vector<DenseView> views{3};
  std::vector<ImageF> depth;
  Rig() {
    for (int i = 0; i < 3; ++i) {
      PinholeCamera& c = views[i].camera;
      c.width = 64;
      c.height = 48;
      c.fx = c.fy = 60;
      c.cx = 32;
      c.cy = 24;
      c.t = Eigen::Vector3d(-0.1 * i, 0, 0);
      depth.emplace_back(64, 48, 1, 5.0f);
    }
  }
  double Consistency(int ref) {
    std::vector<const DenseView*> vp;
    std::vector<const ImageF*> dp;
    for (int i = 0; i < 3; ++i) {
      vp.push_back(&views[i]);
      dp.push_back(&depth[i]);
    }
    std::vector<int> others;
    for (int i = 0; i < 3; ++i)
      if (i != ref) others.push_back(i);
    return CrossViewConsistency(ref, vp, dp, others);
  }
};

TEST(CrossViewConsistency, ExactDepthAgreesWhereverBothOthersSeeThePixel) {
  Rig rig;
  // The camera shifted by 0.1 k m sees the wall point of pixel centre x + 0.5
  // at x + 0.5 - 1.2 k: only columns 0 and 1 fall outside camera 2.
  EXPECT_NEAR(rig.Consistency(0), 62.0 / 64.0, 1e-9);
}

TEST(CrossViewConsistency, DetectsADepthMapThatDisagrees) {
  Rig rig;
  for (float& d : rig.depth[1].vector()) d = 5.5f;  // 10% off: beyond the 2% tolerance.
  EXPECT_EQ(rig.Consistency(0), 0.0);
  for (float& d : rig.depth[1].vector()) d = 5.05f;  // 1% off: within it.
  EXPECT_NEAR(rig.Consistency(0), 62.0 / 64.0, 0.02);
  // Invalid and infinite depths count neither as pixels nor as support.
  for (float& d : rig.depth[0].vector()) d = std::numeric_limits<float>::infinity();
  EXPECT_EQ(rig.Consistency(0), 0.0);
}

TEST(EvaluateDepth, CountsFloatersAndSkySeparately) {
  ImageF gt(4, 1, 1, 10.0f), d(4, 1, 1, 10.0f);
  gt.at(3, 0) = std::numeric_limits<float>::infinity();
  d.at(1, 0) = 8.0f;   // Near floater (< 0.85 g).
  d.at(2, 0) = 10.2f;  // Within 3%.
  d.at(3, 0) = 5.0f;   // Sky estimated near.
  const DepthAccuracy a = EvaluateDepth(d, gt, 10.0);
  EXPECT_EQ(a.pixels, 3);
  EXPECT_EQ(a.sky_pixels, 1);
  EXPECT_NEAR(a.near_floaters, 1.0 / 3, 1e-9);
  EXPECT_NEAR(a.within_3pct, 2.0 / 3, 1e-9);
  EXPECT_NEAR(a.sky_near, 1.0, 1e-9);
}

TEST(AgreeingViews, CountsTheViewsThatSeeTheSurface) {
  Rig rig;
  // A pole 2 m away in front of columns 20-23 of camera 1 hides the wall
  // behind them from it.
  for (int y = 0; y < 48; ++y)
    for (int x = 20; x < 24; ++x) rig.depth[1].at(x, y) = 2.0f;
  const std::vector<const PinholeCamera*> cams = {&rig.views[1].camera, &rig.views[2].camera};
  const std::vector<const ImageF*> maps = {&rig.depth[1], &rig.depth[2]};
  const std::vector<uint8_t> n = AgreeingViews(rig.views[0].camera, rig.depth[0], cams, maps, 0.02);
  ASSERT_EQ(n.size(), 64u * 48u);
  // Camera 1 (0.1 m) sees pixel x at x - 1.2, camera 2 at x - 2.4.
  EXPECT_EQ(n[10 * 64 + 0], 0);   // Outside both.
  EXPECT_EQ(n[10 * 64 + 1], 1);   // Inside camera 1 only (x - 1.2 >= 0 > x - 2.4).
  EXPECT_EQ(n[10 * 64 + 10], 2);
  EXPECT_EQ(n[10 * 64 + 22], 1);  // Hidden from camera 1 by the pole (camera 1 column 20).
  rig.depth[0].at(5, 10) = 0.0f;
  EXPECT_EQ(AgreeingViews(rig.views[0].camera, rig.depth[0], cams, maps, 0.02)[10 * 64 + 5], kNoDepth);
}

TEST(EvaluateDepth, ReportsThePixelsOthersSeeSeparately) {
  ImageF gt(4, 1, 1, 10.0f), d(4, 1, 1, 10.0f);
  d.at(0, 0) = 5.0f;  // A floater where no neighbour sees the surface.
  d.at(1, 0) = 8.0f;  // A floater where two do.
  const std::vector<uint8_t> observers = {0, 2, 3, kNoDepth};
  const DepthAccuracy a = EvaluateDepth(d, gt, 10.0, 0.0, &observers, 2);
  EXPECT_NEAR(a.near_floaters, 0.5, 1e-9);
  EXPECT_EQ(a.observed_pixels, 2);
  EXPECT_NEAR(a.near_floaters_observed, 0.5, 1e-9);
  EXPECT_NEAR(a.within_3pct_observed, 0.5, 1e-9);
  const std::vector<uint8_t> wrong_size = {0, 2};
  EXPECT_THROW(EvaluateDepth(d, gt, 10.0, 0.0, &wrong_size, 2), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth
