#include "reconstruct/depth/flat_regions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "reconstruct/depth/plane_sweep.h"
#include "reconstruct/depth/testing/toy_scene.h"

namespace casual3d::depth {
namespace {

using testing::MakeView;
using testing::ToyCamera;
using testing::ToyRect;
using testing::ToyScene;

constexpr int kWidth = 160, kHeight = 120;
constexpr double kFocal = 160.0;
constexpr double kWallZ = 6.0;

// A textured wall filling the view and, when panel_z > 0, a large uniformly
// coloured panel at that depth in front of it (its silhouette against the
// wall is its whole boundary). At 2.5 m it covers about 64 x 45 pixels of
// the reference, 15% of the image.
ToyScene PanelScene(double panel_z) {
  ToyScene scene;
  scene.rects.push_back({kWallZ, -50, 50, -50, 50, 8.0, 11});
  if (panel_z > 0) {
    ToyRect r{panel_z, -0.5, 0.5, -0.35, 0.35, 0.0, 1};
    r.color = {0.85f, 0.7f, 0.55f};
    scene.rects.push_back(r);
  }
  return scene;
}

// The reference and four neighbours (left, right, up, down) with small
// baselines and different exposure gains, the sweep's cost volume (64 labels
// between 1 and 20 m: one label is about 0.5 px of disparity at a 0.2 m
// baseline) and, as anchors, the winner-takes-all depths of that volume, as
// the dense stage passes them (FlatRegionPriors itself only trusts anchors
// where w_photo is high).
struct Case {
  DenseView ref;
  std::vector<DenseView> nbs;
  ImageF gt;
  CostVolume vol;
  ImageF anchors;

  std::vector<FlatRegionNeighbor> Neighbors() const {
    std::vector<FlatRegionNeighbor> out;
    for (const DenseView& v : nbs) out.push_back({&v.color, v.camera});
    return out;
  }
};

Case MakeCase(const ToyScene& scene, double baseline = 0.2) {
  Case c;
  const DepthRange range{1.0, 20.0};
  c.ref = MakeView(scene, ToyCamera({0, 0, 0}, kWidth, kHeight, kFocal), range, 1.0, 0.0, &c.gt);
  const double gains[4] = {1.15, 0.9, 1.05, 0.93};
  const Eigen::Vector3d centres[4] = {
      {baseline, 0, 0}, {-baseline, 0, 0}, {0, baseline, 0}, {0, -baseline, 0}};
  for (int i = 0; i < 4; ++i)
    c.nbs.push_back(
        MakeView(scene, ToyCamera(centres[i], kWidth, kHeight, kFocal), range, gains[i]));
  SweepOptions sweep;
  sweep.num_depths = 64;
  sweep.num_threads = 2;
  std::vector<const DenseView*> nb_ptrs;
  for (const DenseView& v : c.nbs) nb_ptrs.push_back(&v);
  c.vol = ComputeCostVolume(c.ref, nb_ptrs, sweep);
  c.anchors = WinnerTakesAll(c.vol, 2);
  return c;
}

std::vector<float> Priors(const Case& c, const FlatRegionOptions& options,
                          FlatRegionStats* stats = nullptr) {
  return FlatRegionPriors(c.ref.color, c.vol.photo_weight, c.ref.camera, c.anchors, c.Neighbors(),
                          c.vol, options, stats);
}

long long CountPriors(const std::vector<float>& prior) {
  long long n = 0;
  for (float p : prior) n += !std::isnan(p);
  return n;
}

TEST(FlatRegionOptions, DefaultsAreValidAndBadValuesAreRejected) {
  EXPECT_TRUE(FlatRegionOptions().Check().ok());
  auto bad = [](auto edit) {
    FlatRegionOptions o;
    edit(&o);
    return !o.Check().ok();
  };
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->max_photo_weight = 1.5; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->color_step = 0.0; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->color_spread = -0.1; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->min_area_fraction = 2.0; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->min_region_pixels = 0; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->merge_gap = -1; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->edge_tau = 0.0; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->max_edge_points = 5; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->touch_labels = 0.0; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->behind_fraction = NAN; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->min_touching = 2; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->min_owned = 0; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->owned_margin = -1.0; }));
  EXPECT_TRUE(bad([](FlatRegionOptions* o) { o->adopt_distance = -1; }));
}

// An untextured panel in front of a textured wall: its silhouette's depth,
// measured in the neighbours, gives a plane at the panel's depth over the
// panel, and no prior on the wall. Two depths and baselines.
TEST(FlatRegionPriors, RecoversAnUntexturedPanel) {
  const struct { double z, baseline; } cases[] = {{2.5, 0.2}, {3.5, 0.15}};
  for (const auto& pc : cases) {
    const Case c = MakeCase(PanelScene(pc.z), pc.baseline);
    FlatRegionStats stats;
    const std::vector<float> prior = Priors(c, FlatRegionOptions(), &stats);
    ASSERT_EQ(prior.size(), static_cast<size_t>(kWidth) * kHeight);
    const double truth = c.vol.LabelOfDepth(pc.z);
    int panel = 0, panel_ok = 0, wall = 0, wall_prior = 0;
    double max_err = 0;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        const float p = prior[static_cast<size_t>(y) * kWidth + x];
        if (!std::isnan(p)) {
          EXPECT_GE(p, 0.0f);
          EXPECT_LE(p, c.vol.num_labels - 1.0f);
        }
        if (c.gt.at(x, y) == static_cast<float>(pc.z)) {
          ++panel;
          panel_ok += std::abs(p - truth) <= 1.0;
          if (!std::isnan(p)) max_err = std::max(max_err, std::abs(p - truth));
        } else {
          ++wall;
          wall_prior += !std::isnan(p);
        }
      }
    std::printf(
        "panel at %.1f m (label %.2f), baseline %.2f m: groups %d, fitted %d, edge points %d; "
        "panel pixels within 1 label %d of %d (max error %.3f); wall pixels with a prior %d of "
        "%d\n",
        pc.z, truth, pc.baseline, stats.groups, stats.fitted, stats.edge_points, panel_ok, panel,
        max_err, wall_prior, wall);
    // Measured: 2816 of 2816 (max error 0.48) and 1472 of 1472 (max error 0.36) within 1 label,
    // 1 group fitted from 202 and 152 edge points; no wall pixel with a prior.
    EXPECT_GE(stats.fitted, 1);
    EXPECT_GE(panel_ok, 0.95 * panel);
    EXPECT_LE(wall_prior, 0.002 * wall);
    EXPECT_EQ(stats.pixels, CountPriors(prior));
  }
}

// A thin textured pole in front of the panel cuts it in two: both parts
// join one group and get the panel's plane; the pole gets no prior. (The
// column of panel pixels that the pole's edge covers in part has a mixed
// colour and stays without a prior.)
TEST(FlatRegionPriors, JoinsAPanelThatAPoleCrosses) {
  ToyScene scene = PanelScene(2.5);
  scene.rects.push_back({1.5, -0.04, 0.0, -3, 3, 40.0, 37});
  const Case c = MakeCase(scene);
  FlatRegionStats stats;
  const std::vector<float> prior = Priors(c, FlatRegionOptions(), &stats);
  const double truth = c.vol.LabelOfDepth(2.5);
  int left = 0, left_ok = 0, right = 0, right_ok = 0, pole = 0, pole_prior = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const float p = prior[static_cast<size_t>(y) * kWidth + x];
      const float z = c.gt.at(x, y);
      if (z == 2.5f) {
        const bool ok = std::abs(p - truth) <= 1.0;
        if (x < kWidth / 2) {
          ++left;
          left_ok += ok;
        } else {
          ++right;
          right_ok += ok;
        }
      } else if (z == 1.5f) {
        ++pole;
        pole_prior += !std::isnan(p);
      }
    }
  std::printf(
      "pole across the panel: groups %d, fitted %d; left %d of %d, right %d of %d within 1 label; "
      "pole pixels with a prior %d of %d\n",
      stats.groups, stats.fitted, left_ok, left, right_ok, right, pole_prior, pole);
  // Measured: 1 group, 1 fitted; 1188 of 1232 (the 44 others: the mixed column, no prior), 1408 of
  // 1408; no pole pixel.
  EXPECT_EQ(stats.groups, 1);
  EXPECT_EQ(stats.fitted, 1);
  EXPECT_GE(left_ok, 0.9 * left);
  EXPECT_GE(right_ok, 0.9 * right);
  EXPECT_LE(pole_prior, 0.02 * pole);
}

// Texture everywhere: no flat region, no prior.
TEST(FlatRegionPriors, TexturedSceneGetsNoPriors) {
  const Case c = MakeCase(PanelScene(0.0));
  FlatRegionStats stats;
  const std::vector<float> prior = Priors(c, FlatRegionOptions(), &stats);
  const long long n = CountPriors(prior);
  std::printf("textured scene: %lld pixels with a prior, %d groups, %d fitted\n", n, stats.groups,
              stats.fitted);
  // Measured: no prior, no group.
  EXPECT_LE(n, 0.002 * kWidth * kHeight);
  EXPECT_EQ(stats.fitted, 0);
}

// A flat region below min_area_fraction of the image forms no group.
TEST(FlatRegionPriors, IgnoresRegionsBelowTheMinimumArea) {
  const Case c = MakeCase(PanelScene(2.5));
  FlatRegionOptions opt;
  opt.min_area_fraction = 0.2;  // The panel covers 15%.
  FlatRegionStats stats;
  const std::vector<float> prior = Priors(c, opt, &stats);
  EXPECT_EQ(CountPriors(prior), 0);
  EXPECT_EQ(stats.groups, 0);
  EXPECT_EQ(stats.fitted, 0);
}

TEST(FlatRegionPriors, DisabledOrWithoutNeighboursGivesNoPriors) {
  const Case c = MakeCase(PanelScene(2.5));
  FlatRegionOptions off;
  off.enabled = false;
  FlatRegionStats stats;
  stats.fitted = 5;
  EXPECT_EQ(CountPriors(Priors(c, off, &stats)), 0);
  EXPECT_EQ(stats.fitted, 0);
  const std::vector<float> none = FlatRegionPriors(c.ref.color, c.vol.photo_weight, c.ref.camera,
                                                   c.anchors, {}, c.vol, FlatRegionOptions());
  EXPECT_EQ(none.size(), static_cast<size_t>(kWidth) * kHeight);
  EXPECT_EQ(CountPriors(none), 0);
}

TEST(FlatRegionPriors, RejectsBadOptionsAndSizes) {
  const Case c = MakeCase(PanelScene(2.5));
  const std::vector<FlatRegionNeighbor> nbs = c.Neighbors();
  FlatRegionOptions bad;
  bad.color_step = 0.0;
  EXPECT_THROW(Priors(c, bad), std::invalid_argument);
  const FlatRegionOptions opt;
  const ImageF small(kWidth / 2, kHeight / 2, 1, 0.0f);
  EXPECT_THROW(FlatRegionPriors(c.ref.color, small, c.ref.camera, c.anchors, nbs, c.vol, opt),
               std::invalid_argument);
  EXPECT_THROW(
      FlatRegionPriors(c.ref.color, c.vol.photo_weight, c.ref.camera, small, nbs, c.vol, opt),
      std::invalid_argument);
  EXPECT_THROW(
      FlatRegionPriors(c.ref.gray, c.vol.photo_weight, c.ref.camera, c.anchors, nbs, c.vol, opt),
      std::invalid_argument);
  EXPECT_THROW(
      FlatRegionPriors(c.ref.color, c.vol.photo_weight,
                       c.ref.camera.Resized(kWidth / 2, kHeight / 2), c.anchors, nbs, c.vol, opt),
      std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth
