#include "reconstruct/depth/visibility_filter.h"

#include <gtest/gtest.h>

#include <cmath>

#include "reconstruct/depth/testing/toy_scene.h"

namespace casual3d::depth {
namespace {

using testing::MakeView;
using testing::ToyCamera;
using testing::ToyScene;

// 220 labels from 0.5 to 50 m.
constexpr double kInvStep = (1 / 0.5 - 1 / 50.0) / 219;

// Five views of the toy scene, ray-cast depth (the sky at 50 m, the sweep's
// far bound).
struct Rig {
  std::vector<DenseView> views;
  std::vector<ImageF> depth;
  std::vector<const PinholeCamera*> cameras;
  std::vector<const ImageF*> grays;

  Rig() : depth(5) {
    const ToyScene scene = ToyScene::Default();
    const Eigen::Vector3d centres[5] = {
        {0, 0, 0}, {0.15, 0, 0}, {-0.15, 0, 0}, {0, 0.12, 0}, {0, -0.12, 0}};
    for (int i = 0; i < 5; ++i) {
      views.push_back(
          MakeView(scene, ToyCamera(centres[i], 120, 90, 100), {0.5, 50.0}, 1.0, 0.0, &depth[i]));
      for (float& d : depth[i].vector())
        if (!std::isfinite(d)) d = 50.0f;
    }
    for (const DenseView& v : views) {
      cameras.push_back(&v.camera);
      grays.push_back(&v.gray);
    }
  }
  std::vector<const ImageF*> Maps(const ImageF& ref) const {
    return {&ref, &depth[1], &depth[2], &depth[3], &depth[4]};
  }
};

TEST(VisibilityFilter, LeavesConsistentMapsAlone) {
  const Rig rig;
  VisibilityStats stats;
  const auto moves = CheckFreeSpace(0, rig.cameras, rig.Maps(rig.depth[0]), rig.grays, {1, 2, 3, 4},
                                    kInvStep, VisibilityFilterOptions(), &stats);
  // Exact maps: nothing is seen through, whatever the depth edges.
  EXPECT_EQ(stats.flagged, 0);
  EXPECT_TRUE(moves.empty());
}

TEST(VisibilityFilter, MovesAFloaterBackOntoTheSurfaceBehindIt) {
  const Rig rig;
  ImageF ref = rig.depth[0];
  for (int y = 70; y < 80; ++y)
    for (int x = 10; x < 20; ++x) ref.at(x, y) *= 0.4f;
  VisibilityStats stats;
  const auto moves = CheckFreeSpace(0, rig.cameras, rig.Maps(ref), rig.grays, {1, 2, 3, 4},
                                    kInvStep, VisibilityFilterOptions(), &stats);
  ASSERT_FALSE(moves.empty());
  EXPECT_EQ(stats.replaced, static_cast<long long>(moves.size()));
  int on_surface = 0;
  for (size_t k = 0; k < moves.size(); ++k) {
    const int x = moves[k].index % 120, y = moves[k].index / 120;
    if (k > 0) {
      EXPECT_GT(moves[k].index, moves[k - 1].index);
    }
    // Only the floater moves, and only farther.
    EXPECT_TRUE(x >= 10 && x < 20 && y >= 70 && y < 80) << x << "," << y;
    EXPECT_GT(moves[k].depth, ref.at(x, y));
    const float truth = rig.depth[0].at(x, y);
    on_surface += std::abs(moves[k].depth - truth) <= 0.02f * truth;
  }
  // Every floater pixel is seen through by the four views (the patch lies
  // inside all of them) and lands on the true surface within a pixel's
  // splatting error.
  EXPECT_EQ(stats.flagged, 100);
  EXPECT_GE(on_surface, 95);
}

TEST(VisibilityFilter, KeepsAThinObjectThatOtherMapsLostWhenThePhotosShowIt) {
  const Rig rig;
  // The pole (1.2 m, columns 87-90 of the reference) is lost from every
  // other map: they hold the wall's depth there.
  std::vector<ImageF> lost(rig.depth.begin(), rig.depth.end());
  for (int k = 1; k < 5; ++k)
    for (float& d : lost[k].vector())
      if (d < 1.5f) d = 6.0f;
  const std::vector<const ImageF*> maps = {&rig.depth[0], &lost[1], &lost[2], &lost[3], &lost[4]};
  int pole = 0;
  for (float d : rig.depth[0].vector()) pole += d < 1.5f;
  ASSERT_GT(pole, 300);
  auto moved_off_pole = [&](const VisibilityFilterOptions& options) {
    VisibilityStats stats;
    int moved = 0;
    for (const DepthReplacement& m :
         CheckFreeSpace(0, rig.cameras, maps, rig.grays, {1, 2, 3, 4}, kInvStep, options, &stats))
      moved += rig.depth[0].data()[m.index] < 1.5f;
    EXPECT_GE(stats.flagged, 0.9 * pole);  // The maps alone condemn it ...
    return moved;
  };
  VisibilityFilterOptions options;
  options.photo_stride = 1;  // The pole is 4 pixels wide: every window pixel counts.
  options.photo_gate = false;
  EXPECT_GE(moved_off_pole(options), 0.9 * pole);
  // ... the photos keep most of it. What moves are the pole's two mixed
  // edge columns and stretches where its texture matches the wall's grey.
  options.photo_gate = true;
  EXPECT_LE(moved_off_pole(options), 0.25 * pole);
}

TEST(VisibilityFilter, NeedsEnoughViewsThatSeeThrough) {
  const Rig rig;
  ImageF ref = rig.depth[0];
  for (int y = 70; y < 80; ++y)
    for (int x = 10; x < 20; ++x) ref.at(x, y) *= 0.4f;
  VisibilityFilterOptions options;
  options.min_violations = 5;  // More than the four other views.
  EXPECT_TRUE(
      CheckFreeSpace(0, rig.cameras, rig.Maps(ref), rig.grays, {1, 2, 3, 4}, kInvStep, options)
          .empty());
  options.min_violations = 2;
  options.max_views = 1;  // One view cannot outvote.
  EXPECT_TRUE(
      CheckFreeSpace(0, rig.cameras, rig.Maps(ref), rig.grays, {1, 2, 3, 4}, kInvStep, options)
          .empty());
}

TEST(VisibilityFilter, NeverMovesADepthNearer) {
  const Rig rig;
  // A patch pushed behind its true surface is occluded in the other views,
  // which say nothing about it.
  ImageF ref = rig.depth[0];
  for (int y = 40; y < 50; ++y)
    for (int x = 55; x < 65; ++x) ref.at(x, y) = std::min(50.0f, ref.at(x, y) * 1.5f);
  VisibilityStats stats;
  const auto moves = CheckFreeSpace(0, rig.cameras, rig.Maps(ref), rig.grays, {1, 2, 3, 4},
                                    kInvStep, VisibilityFilterOptions(), &stats);
  for (const DepthReplacement& m : moves) EXPECT_GT(m.depth, ref.data()[m.index]);
  EXPECT_EQ(stats.flagged, 0);
}

TEST(VisibilityFilter, SkipsPixelsWithoutDepth) {
  const Rig rig;
  // The floater patch again, with a row of it and row 10 without depth in the
  // reference; one other view has no depth at all (0) and another none but
  // NaN: neither sees through anything (a missing depth is not a far one).
  ImageF ref = rig.depth[0];
  for (int y = 70; y < 80; ++y)
    for (int x = 10; x < 20; ++x) ref.at(x, y) *= 0.4f;
  for (int x = 0; x < 120; ++x) {
    ref.at(x, 10) = std::numeric_limits<float>::quiet_NaN();
    ref.at(x, 75) = 0.0f;
  }
  ImageF zero = rig.depth[1], missing = rig.depth[2];
  for (float& d : zero.vector()) d = 0.0f;
  for (float& d : missing.vector()) d = std::numeric_limits<float>::quiet_NaN();
  const std::vector<const ImageF*> maps = {&ref, &zero, &missing, &rig.depth[3], &rig.depth[4]};
  VisibilityFilterOptions options;
  options.min_violations = 3;  // Only views 3 and 4 can see through the patch.
  VisibilityStats stats;
  EXPECT_TRUE(
      CheckFreeSpace(0, rig.cameras, maps, rig.grays, {1, 2, 3, 4}, kInvStep, options, &stats)
          .empty());
  EXPECT_EQ(stats.flagged, 0);
  options.min_violations = 2;
  stats = VisibilityStats();
  const auto moves =
      CheckFreeSpace(0, rig.cameras, maps, rig.grays, {1, 2, 3, 4}, kInvStep, options, &stats);
  EXPECT_EQ(stats.flagged, 90);  // The patch but its row without depth.
  for (const DepthReplacement& m : moves) EXPECT_NE(m.index / 120, 75);
}

TEST(VisibilityFilter, OptionsAreChecked) {
  EXPECT_TRUE(VisibilityFilterOptions().Check().ok());
  auto bad = [](auto change) {
    VisibilityFilterOptions o;
    change(&o);
    return !o.Check().ok();
  };
  EXPECT_TRUE(bad([](VisibilityFilterOptions* o) { o->tolerance = 0; }));
  EXPECT_TRUE(bad([](VisibilityFilterOptions* o) { o->tolerance = 1.5; }));
  EXPECT_TRUE(bad([](VisibilityFilterOptions* o) { o->tolerance_labels = -1; }));
  EXPECT_TRUE(bad([](VisibilityFilterOptions* o) { o->min_violations = 0; }));
  EXPECT_TRUE(bad([](VisibilityFilterOptions* o) { o->max_views = 0; }));
  EXPECT_TRUE(bad([](VisibilityFilterOptions* o) { o->max_views = 256; }));
  EXPECT_TRUE(bad([](VisibilityFilterOptions* o) { o->rounds = 11; }));
  EXPECT_TRUE(bad([](VisibilityFilterOptions* o) { o->photo_margin = -0.1; }));
  EXPECT_TRUE(bad([](VisibilityFilterOptions* o) { o->photo_radius = 11; }));
  EXPECT_TRUE(bad([](VisibilityFilterOptions* o) { o->photo_stride = 0; }));
}

}  // namespace
}  // namespace casual3d::depth
