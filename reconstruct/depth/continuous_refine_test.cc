#include "reconstruct/depth/continuous_refine.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "reconstruct/depth/sublabel_refine.h"
#include "reconstruct/depth/testing/toy_scene.h"

namespace casual3d::depth {
namespace {

using testing::MakeView;
using testing::ToyCamera;
using testing::ToyScene;

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

struct PlaneCase {
  DenseView ref, a, b, c;
  ImageF gt;
  CostVolume vol;
  SweepOptions sweep;
};

// A textured plane at `z` metres seen by a reference and three neighbours
// with different exposures; 60 labels between 1 and 20 m, so that one label
// is a disparity step of about 1.1 px for the 0.2 m baseline.
PlaneCase MakePlane(double z, double baseline = 0.2) {
  PlaneCase pc;
  ToyScene scene;
  scene.rects.push_back({z, -50, 50, -50, 50, 8.0, 5});
  const DepthRange range{1.0, 20.0};
  pc.ref = MakeView(scene, ToyCamera({0, 0, 0}, 120, 90, 150), range, 1.0, 0.0, &pc.gt);
  pc.a = MakeView(scene, ToyCamera({baseline, 0, 0}, 120, 90, 150), range, 1.3, -0.08);
  pc.b = MakeView(scene, ToyCamera({-baseline, 0, 0}, 120, 90, 150), range, 0.8, 0.1);
  pc.c = MakeView(scene, ToyCamera({0, 0.75 * baseline, 0}, 120, 90, 150), range, 1.1, 0.0);
  pc.sweep.num_depths = 60;
  pc.sweep.num_threads = 2;
  pc.vol = ComputeCostVolume(pc.ref, {&pc.a, &pc.b, &pc.c}, pc.sweep);
  return pc;
}

void CheckPlaneBetweenLabels(double baseline) {
  // The true plane lies 0.4 labels from the nearest label.
  const double z = 1.0 / (1.0 + (0.05 - 1.0) * 30.4 / 59.0);
  PlaneCase pc = MakePlane(z, baseline);
  const double truth = pc.vol.LabelOfDepth(z);
  ASSERT_NEAR(truth, 30.4, 1e-6);
  const int w = pc.vol.width, h = pc.vol.height;
  std::vector<int> labels(static_cast<size_t>(w) * h, 30);
  SubLabelOptions sub;
  const std::vector<float> start = FitSubLabel(pc.vol, labels, sub, 2);
  ContinuousRefineOptions opt;
  opt.enabled = true;
  const std::vector<float> refined =
      RefineContinuous(pc.ref, {&pc.a, &pc.b, &pc.c}, pc.vol, labels, start, pc.sweep, opt, 2);
  std::vector<double> err_start, err_refined;
  for (int y = 12; y < h - 12; ++y)
    for (int x = 12; x < w - 12; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      err_start.push_back(std::abs(start[p] - truth));
      err_refined.push_back(std::abs(refined[p] - truth));
      EXPECT_LE(std::abs(refined[p] - 30.0f), opt.search_labels + 1e-4);
    }
  const double m_start = Median(err_start), m_refined = Median(err_refined);
  std::printf("baseline %.2f m: median label error %.4f (parabola) -> %.4f (refined)\n", baseline,
              m_start, m_refined);
  // Measured (5x5 window): 0.085 -> 0.064, 0.058 -> 0.032, 0.081 -> 0.023.
  EXPECT_LT(m_refined, 0.07) << "parabola alone: " << m_start;
  EXPECT_LT(m_refined, 0.8 * m_start);
}

TEST(RefineContinuous, LocatesAPlaneBetweenLabels) {
  for (double baseline : {0.2, 0.4, 0.6}) CheckPlaneBetweenLabels(baseline);
}

TEST(RefineContinuous, StaysWithinTheSearchRangeAndLeavesFlatPixels) {
  PlaneCase pc = MakePlane(3.0);
  const int w = pc.vol.width, h = pc.vol.height;
  const size_t np = static_cast<size_t>(w) * h;
  // Start three labels off the truth: the search may only move one label.
  const int truth = static_cast<int>(std::lround(pc.vol.LabelOfDepth(3.0)));
  std::vector<int> labels(np, truth + 3);
  std::vector<float> start(np, static_cast<float>(truth + 3));
  // Mark a block as textureless: it must keep its start value.
  for (int y = 40; y < 50; ++y)
    for (int x = 50; x < 60; ++x) pc.vol.photo_weight.at(x, y) = 0.0f;
  ContinuousRefineOptions opt;
  opt.enabled = true;
  const std::vector<float> refined =
      RefineContinuous(pc.ref, {&pc.a, &pc.b, &pc.c}, pc.vol, labels, start, pc.sweep, opt, 1);
  int moved_towards_truth = 0, interior = 0;
  for (int y = 12; y < h - 12; ++y)
    for (int x = 12; x < w - 12; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      EXPECT_GE(refined[p], truth + 2 - 1e-4);
      EXPECT_LE(refined[p], truth + 4 + 1e-4);
      if (x >= 50 && x < 60 && y >= 40 && y < 50) {
        EXPECT_EQ(refined[p], start[p]);
      } else {
        ++interior;
        moved_towards_truth += refined[p] < truth + 2.5f;
      }
    }
  EXPECT_GT(moved_towards_truth, 0.9 * interior);
}

// A plane case with every pixel at MRF label 10 and start value `start_label`.
struct FlatStart {
  PlaneCase pc = MakePlane(4.0);
  size_t np = static_cast<size_t>(pc.vol.width) * pc.vol.height;
  std::vector<int> labels = std::vector<int>(np, 10);
  std::vector<float> start;
  explicit FlatStart(float start_label) : start(np, start_label) {}
};

TEST(RefineContinuous, DisabledOrWithoutNeighboursReturnsTheStart) {
  FlatStart f(10.25f);
  PlaneCase& pc = f.pc;
  const std::vector<int>& labels = f.labels;
  const std::vector<float>& start = f.start;
  ContinuousRefineOptions off;
  off.enabled = false;
  EXPECT_EQ(RefineContinuous(pc.ref, {&pc.a}, pc.vol, labels, start, pc.sweep, off), start);
  ContinuousRefineOptions on;
  on.enabled = true;
  EXPECT_EQ(RefineContinuous(pc.ref, {}, pc.vol, labels, start, pc.sweep, on), start);
}

TEST(RefineContinuous, RejectsBadOptionsAndSizes) {
  FlatStart f(10.0f);
  PlaneCase& pc = f.pc;
  const std::vector<int>& labels = f.labels;
  const std::vector<float>& start = f.start;
  const size_t np = f.np;
  ContinuousRefineOptions bad;
  bad.coarse_step = 2.0;  // Larger than search_labels.
  EXPECT_THROW(RefineContinuous(pc.ref, {&pc.a}, pc.vol, labels, start, pc.sweep, bad),
               std::invalid_argument);
  std::vector<float> short_start(np - 1, 10.0f);
  EXPECT_THROW(RefineContinuous(pc.ref, {&pc.a}, pc.vol, labels, short_start, pc.sweep,
                                ContinuousRefineOptions()),
               std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth
