#include "reconstruct/depth/plane_sweep.h"

#include <cmath>

#include <gtest/gtest.h>

#include "reconstruct/depth/testing/toy_scene.h"

namespace casual3d::depth {
namespace {

using testing::MakeView;
using testing::ToyCamera;
using testing::ToyRect;
using testing::ToyScene;

// Fraction of interior pixels whose WTA label is within `tol` labels of the truth.
double FractionWithinLabels(const CostVolume& vol, const ImageF& wta, const ImageF& gt, double tol,
                            int border) {
  int ok = 0, total = 0;
  for (int y = border; y < wta.height() - border; ++y)
    for (int x = border; x < wta.width() - border; ++x) {
      ++total;
      if (wta.at(x, y) > 0 &&
          std::abs(vol.LabelOfDepth(wta.at(x, y)) - vol.LabelOfDepth(gt.at(x, y))) <= tol)
        ++ok;
    }
  return static_cast<double>(ok) / total;
}

TEST(PlaneSweep, RecoversAPlaneDespiteExposureChanges) {
  ToyScene scene;
  scene.rects.push_back({3.0, -50, 50, -50, 50, 8.0, 5});
  const DepthRange range{1.0, 20.0};
  ImageF gt;
  const DenseView ref = MakeView(scene, ToyCamera({0, 0, 0}, 160, 120, 150), range, 1.0, 0.0, &gt);
  // Different gain and offset per neighbour: ZNCC must not care.
  const DenseView a = MakeView(scene, ToyCamera({0.2, 0, 0}, 160, 120, 150), range, 1.3, -0.08);
  const DenseView b = MakeView(scene, ToyCamera({-0.2, 0, 0}, 160, 120, 150), range, 0.8, 0.1);
  const DenseView c = MakeView(scene, ToyCamera({0, 0.15, 0}, 160, 120, 150), range, 1.1, 0.0);
  SweepOptions opt;
  opt.num_threads = 2;
  const CostVolume vol = ComputeCostVolume(ref, {&a, &b, &c}, opt);
  ASSERT_EQ(vol.num_labels, 220);
  ASSERT_EQ(vol.cost.size(), 160u * 120u * 220u);
  EXPECT_NEAR(vol.DepthOfLabel(0), 1.0, 1e-9);
  EXPECT_NEAR(vol.DepthOfLabel(219), 20.0, 1e-9);
  const ImageF wta = WinnerTakesAll(vol, 2);
  // Away from the image border (where neighbours do not overlap), nearly all
  // pixels pick the true plane's label or its neighbour.
  EXPECT_GE(FractionWithinLabels(vol, wta, gt, 1.0, 12), 0.97);
  // Costs are normalised to [0, 1] and the textured plane gets w_photo near 1.
  float mn = 2, mx = -1;
  for (float v : vol.cost) {
    mn = std::min(mn, v);
    mx = std::max(mx, v);
  }
  EXPECT_GE(mn, 0.0f);
  EXPECT_LE(mx, 1.0f);
  EXPECT_GT(vol.photo_weight.at(80, 60), 0.7f);
}

TEST(PlaneSweep, BestKAveragingSurvivesAnOccludingNeighbour) {
  // The plane at 4 m; a board at 1 m hides the centre from neighbour `occ` only.
  ToyScene scene;
  scene.rects.push_back({4.0, -50, 50, -50, 50, 6.0, 9});
  ToyScene occluded = scene;
  occluded.rects.push_back({1.0, 0.35, 0.9, -0.4, 0.4, 30.0, 3});
  const DepthRange range{0.5, 30.0};
  ImageF gt;
  const DenseView ref = MakeView(scene, ToyCamera({0, 0, 0}, 160, 120, 150), range, 1.0, 0.0, &gt);
  const DenseView a = MakeView(scene, ToyCamera({0.25, 0, 0}, 160, 120, 150), range);
  const DenseView b = MakeView(scene, ToyCamera({-0.25, 0, 0}, 160, 120, 150), range);
  // The occluder sits in front of this neighbour only (it is off to the side
  // of the reference's view of the plane).
  const DenseView occ = MakeView(occluded, ToyCamera({0.6, 0, 0}, 160, 120, 150), range);
  SweepOptions opt;
  opt.best_k = 2;
  const CostVolume vol = ComputeCostVolume(ref, {&a, &b, &occ}, opt);
  EXPECT_GE(FractionWithinLabels(vol, WinnerTakesAll(vol), gt, 1.0, 14), 0.95);
}

TEST(PlaneSweep, RejectsInvalidOptionsAndInputs) {
  SweepOptions opt;
  opt.num_depths = 1;
  EXPECT_FALSE(opt.Check().ok());
  opt = SweepOptions();
  opt.window_radius = 0;
  EXPECT_FALSE(opt.Check().ok());
  ToyScene scene = ToyScene::Default();
  const DenseView ref = MakeView(scene, ToyCamera({0, 0, 0}, 32, 24, 30), {1.0, 10.0});
  EXPECT_THROW(ComputeCostVolume(ref, {}, SweepOptions()), std::invalid_argument);
  DenseView bad = ref;
  bad.range = {5.0, 2.0};
  EXPECT_THROW(ComputeCostVolume(bad, {&ref}, SweepOptions()), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth
