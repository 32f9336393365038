#include "reconstruct/depth/dense_free_space.h"

#include <atomic>
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "reconstruct/depth/testing/toy_scene.h"

namespace casual3d::depth {
namespace {

using testing::MakeView;
using testing::Render;
using testing::ToyCamera;
using testing::ToyScene;

// Five views of the toy scene. The depth maps of photos 0 and 1 hold a
// floater (a patch at 1 m that the photos do not show) in front of the wall;
// photo 1 is checked against views that see through it, photo 0 (with
// max_views 2) against photo 1, which agrees with it, and photo 2, which
// sees through it: round 0 moves photo 1's floater back, and only then
// does round 1 move photo 0's.
struct Rig {
  DensePlan plan;
  std::vector<ImageF> depth;
  std::vector<CostVolume> shells;

  Rig() : depth(5), shells(5) {
    const ToyScene scene = ToyScene::Default();
    ToyScene floating = scene;
    floating.rects.push_back({1.0, -0.35, -0.2, 0.1, 0.3, 0.0, 1, {0.9f, 0.1f, 0.1f}});
    const Eigen::Vector3d centres[5] = {{0, 0, 0}, {0.15, 0, 0}, {-0.15, 0, 0}, {0, 0.12, 0}, {0, -0.12, 0}};
    for (int i = 0; i < 5; ++i) {
      const PinholeCamera camera = ToyCamera(centres[i], 120, 90, 100);
      DenseView v = MakeView(scene, camera, {0.5, 50.0}, 1.0, 0.0, &depth[i]);
      if (i < 2) depth[i] = Render(floating, camera).depth;
      for (float& d : depth[i].vector())
        if (!std::isfinite(d)) d = 50.0f;
      v.camera_full = camera;
      v.gray_full = v.gray;
      plan.ws.views.push_back(std::move(v));
      // 220 labels from 0.5 to 50 m.
      shells[i].num_labels = 220;
      shells[i].inv_near = 1 / 0.5;
      shells[i].inv_far = 1 / 50.0;
    }
    plan.ws.ranked_neighbors = {{1, 2, 3, 4}, {3, 4, 0, 2}, {0, 1, 3, 4}, {0, 4, 1, 2}, {0, 3, 1, 2}};
  }
};

VisibilityFilterOptions TwoViewsThreeRounds() {
  VisibilityFilterOptions options;
  options.max_views = 2;
  options.rounds = 3;
  return options;
}

// The check as it ran with every map in memory: each round checks every
// photo against all maps as the round found them, then applies its moves.
std::vector<ImageF> InMemoryRounds(const Rig& rig, const VisibilityFilterOptions& options,
                                   std::vector<RoundMoves>* rounds) {
  const int n = rig.plan.size();
  std::vector<ImageF> depth = rig.depth;
  std::vector<const PinholeCamera*> cameras;
  std::vector<const ImageF*> maps, grays;
  for (int i = 0; i < n; ++i) {
    cameras.push_back(&rig.plan.ws.views[i].camera_full);
    maps.push_back(&depth[i]);
    grays.push_back(&rig.plan.ws.views[i].gray_full);
  }
  for (int round = 0; round < options.rounds; ++round) {
    RoundMoves moves(n);
    for (int i = 0; i < n; ++i) {
      const LabelGrid grid{rig.shells[i].inv_near, rig.shells[i].inv_far, rig.shells[i].num_labels};
      moves[i] = CheckFreeSpace(i, cameras, maps, grays, rig.plan.ws.ranked_neighbors[i], grid.InvStep(), options);
    }
    for (int i = 0; i < n; ++i)
      for (const DepthReplacement& m : moves[i]) depth[i].data()[m.index] = m.depth;
    rounds->push_back(std::move(moves));
  }
  return depth;
}

std::shared_ptr<const ImageF> Owned(const ImageF& image) { return std::make_shared<const ImageF>(image); }

TEST(DenseFreeSpaceTest, StreamedRoundsGiveTheInMemoryResult) {
  const Rig rig;
  const VisibilityFilterOptions options = TwoViewsThreeRounds();
  std::vector<RoundMoves> expected_rounds;
  const std::vector<ImageF> expected = InMemoryRounds(rig, options, &expected_rounds);
  // The rig does what it is for: round 1 moves what round 0 could not.
  ASSERT_EQ(expected_rounds.size(), 3u);
  EXPECT_GT(expected_rounds[0][1].size(), 50u);
  EXPECT_TRUE(expected_rounds[0][0].empty());
  EXPECT_GT(expected_rounds[1][0].size(), 50u);

  for (int threads : {1, 3}) {
    std::atomic<int> depth_reads{0}, gray_reads{0};
    const FreeSpaceResult result = CheckFreeSpaceRounds(
        rig.plan, rig.shells, options, threads,
        [&](int i) {
          ++depth_reads;
          return Owned(rig.depth[i]);
        },
        [&](int i) {
          ++gray_reads;
          return Owned(rig.plan.ws.views[i].gray_full);
        });
    ASSERT_EQ(result.rounds.size(), expected_rounds.size());
    for (size_t r = 0; r < expected_rounds.size(); ++r)
      for (int i = 0; i < rig.plan.size(); ++i) {
        ASSERT_EQ(result.rounds[r][i].size(), expected_rounds[r][i].size()) << "round " << r << ", photo " << i;
        for (size_t k = 0; k < expected_rounds[r][i].size(); ++k) {
          EXPECT_EQ(result.rounds[r][i][k].index, expected_rounds[r][i][k].index);
          EXPECT_EQ(result.rounds[r][i][k].depth, expected_rounds[r][i][k].depth);
        }
      }
    for (int i = 0; i < rig.plan.size(); ++i) {
      const auto final_map = AfterMoves(Owned(rig.depth[i]), result.rounds, i, options.rounds);
      EXPECT_EQ(final_map->vector(), expected[i].vector()) << "photo " << i;
      long long moved = 0;
      for (const RoundMoves& round : expected_rounds) moved += static_cast<long long>(round[i].size());
      EXPECT_EQ(result.stats[i].replaced, moved);
    }
    // The caches hold every photo here: each grey image is read once, each
    // map once per round.
    EXPECT_EQ(gray_reads, 5);
    EXPECT_EQ(depth_reads, 5 * options.rounds);
  }
}

TEST(DenseFreeSpaceTest, ViewsAreThePhotoAndItsFirstRankedNeighbours) {
  LoadedWorkspace ws;
  ws.ranked_neighbors = {{3, 1, 2}, {0, 2, 3}, {1, 0, 3}, {2, 1, 0}};
  EXPECT_EQ(FreeSpaceViews(ws, 0, 2), (std::vector<int>{0, 3, 1}));
  EXPECT_EQ(FreeSpaceViews(ws, 2, 12), (std::vector<int>{2, 1, 0, 3}));
  ws.ranked_neighbors[1] = {1, 0, 2};  // A photo listed among its own neighbours is skipped.
  EXPECT_EQ(FreeSpaceViews(ws, 1, 1), (std::vector<int>{1, 0}));
}

TEST(DenseFreeSpaceTest, MovesApplyInRoundOrder) {
  const auto map = std::make_shared<const ImageF>(3, 1, 1, 1.0f);
  std::vector<RoundMoves> rounds(2, RoundMoves(2));
  rounds[0][1] = {{0, 2.0f}, {2, 3.0f}};
  rounds[1][1] = {{2, 4.0f}};
  EXPECT_EQ(AfterMoves(map, rounds, 0, 2).get(), map.get());  // No moves: the map itself.
  EXPECT_EQ(AfterMoves(map, rounds, 1, 1)->vector(), (std::vector<float>{2.0f, 1.0f, 3.0f}));
  EXPECT_EQ(AfterMoves(map, rounds, 1, 2)->vector(), (std::vector<float>{2.0f, 1.0f, 4.0f}));
  EXPECT_EQ(map->vector(), (std::vector<float>{1.0f, 1.0f, 1.0f}));  // Untouched.
}

}  // namespace
}  // namespace casual3d::depth
