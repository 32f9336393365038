#include "reconstruct/depth/gc_filter.h"

#include <gtest/gtest.h>

#include "reconstruct/depth/testing/toy_scene.h"

namespace casual3d::depth {
namespace {

using testing::MakeView;
using testing::ToyCamera;
using testing::ToyScene;

TEST(GcFilter, KeepsConsistentPixelsAndRemovesFloatersAndVisibilityViolations) {
  const ToyScene scene = ToyScene::Default();
  const DepthRange range{0.5, 50.0};
  std::vector<DenseView> views;
  std::vector<ImageF> depth(4);
  const Eigen::Vector3d centres[4] = {{0, 0, 0}, {0.15, 0, 0}, {-0.15, 0, 0}, {0, 0.12, 0}};
  for (int i = 0; i < 4; ++i) {
    views.push_back(MakeView(scene, ToyCamera(centres[i], 120, 90, 100), range, 1.0, 0.0, &depth[i]));
    for (float& d : depth[i].vector())
      if (!std::isfinite(d)) d = 50.0f;  // The sweep's far bound for the sky.
  }
  // Corrupt the reference: a floater patch at 40% of the true depth.
  ImageF ref = depth[0];
  for (int y = 70; y < 80; ++y)
    for (int x = 10; x < 20; ++x) ref.at(x, y) *= 0.4f;
  std::vector<const DenseView*> vp;
  std::vector<const ImageF*> dp = {&ref, &depth[1], &depth[2], &depth[3]};
  for (const auto& v : views) vp.push_back(&v);
  const double inv_step = (1 / 0.5 - 1 / 50.0) / 219;
  const ImageF out = GeometricConsistencyFilter(0, vp, dp, {1, 2, 3}, inv_step, GcFilterOptions(), 2);
  int floater_kept = 0;
  for (int y = 70; y < 80; ++y)
    for (int x = 10; x < 20; ++x) floater_kept += out.at(x, y) > 0;
  EXPECT_EQ(floater_kept, 0);
  // Most true pixels survive (those near depth edges or seen by fewer than 2
  // other views may not).
  int kept = 0, total = 0;
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 120; ++x) {
      if (y >= 70 && y < 80 && x >= 10 && x < 20) continue;
      ++total;
      kept += out.at(x, y) > 0;
    }
  EXPECT_GE(kept, 0.85 * total);
  // A point pushed behind the true surface is not a violation but loses support.
  ImageF behind = depth[0];
  behind.at(60, 45) *= 1.5f;
  dp[0] = &behind;
  const ImageF out2 = GeometricConsistencyFilter(0, vp, dp, {1, 2, 3}, inv_step, GcFilterOptions(), 1);
  EXPECT_EQ(out2.at(60, 45), 0.0f);
  EXPECT_GT(out2.at(61, 45), 0.0f);
}

}  // namespace
}  // namespace casual3d::depth
