#include "reconstruct/depth/neighbor_selection.h"

#include <gtest/gtest.h>

namespace casual3d::depth {
namespace {

TEST(RankNeighbors, PrefersOverlapWithBaselineAndFallsBackToGeometry) {
  // Four cameras looking at +Z; points at z = 5 seen by views 0..2 only.
  std::vector<NeighborInput> v(4);
  v[0].center = {0, 0, 0};
  v[1].center = {0.02, 0, 0};  // Tiny baseline.
  v[2].center = {0.4, 0, 0};   // Good baseline.
  v[3].center = {0.2, 0, 0};   // No shared points.
  std::vector<std::pair<long long, Eigen::Vector3d>> pts;
  for (int i = 0; i < 30; ++i) {
    pts.push_back({i, Eigen::Vector3d(0.1 * (i % 6), 0.1 * (i / 6), 5.0)});
    for (int c = 0; c < 3; ++c) v[c].point_ids.push_back(i);
  }
  const auto ranked = RankNeighbors(v, pts, NeighborOptions());
  ASSERT_EQ(ranked.size(), 4u);
  EXPECT_EQ(ranked[0], (std::vector<int>{2, 1, 3}));
  // View 3 shares nothing: geometry fallback orders by baseline (capped at the median).
  ASSERT_EQ(ranked[3].size(), 3u);
  EXPECT_EQ(ranked[3].back(), 1);  // The smallest baseline (0.18 m) comes last.
}

TEST(RankNeighbors, CoverageGivesEveryPartOfTheFramePartners) {
  // Reference 0 looks at +Z. The left half of its points is seen by views
  // 1-3 (baselines 0.3-0.4 m, the best scores), the right half only by
  // views 4 and 5 (fewer points, so lower scores).
  std::vector<NeighborInput> v(6);
  v[1].center = {0.30, 0, 0};
  v[2].center = {0.35, 0, 0};
  v[3].center = {0.40, 0, 0};
  v[4].center = {-0.40, 0, 0};
  v[5].center = {-0.30, 0, 0};
  std::vector<std::pair<long long, Eigen::Vector3d>> pts;
  for (int i = 0; i < 40; ++i) {
    const bool left = i < 20;
    pts.push_back({i, Eigen::Vector3d(left ? -1.0 - 0.05 * i : 1.0 + 0.05 * i, 0.1 * (i % 5), 5.0)});
    v[0].point_ids.push_back(i);
    if (left) {
      for (int c = 1; c <= 3; ++c) v[c].point_ids.push_back(i);
    } else {
      if (i < 32) v[4].point_ids.push_back(i);
      if (i < 30) v[5].point_ids.push_back(i);
    }
  }
  NeighborOptions plain;
  plain.coverage_k = 0;
  EXPECT_EQ(RankNeighbors(v, pts, plain)[0], (std::vector<int>{3, 2, 1, 4, 5}));
  // Coverage 2: after the two best, the left half has two partners, so the
  // views of the right half come before the third view of the left half.
  NeighborOptions cover;
  cover.coverage_k = 2;
  EXPECT_EQ(RankNeighbors(v, pts, cover)[0], (std::vector<int>{3, 2, 4, 5, 1}));
  // Coverage 1: the right half needs one partner; then the rest by score.
  cover.coverage_k = 1;
  EXPECT_EQ(RankNeighbors(v, pts, cover)[0], (std::vector<int>{3, 4, 2, 1, 5}));
}

TEST(RankNeighbors, RejectsBadCoverageOptions) {
  NeighborOptions o;
  o.coverage_k = 17;
  EXPECT_FALSE(o.Check().ok());
  o.coverage_k = 2;
  o.coverage_picks = 0;
  EXPECT_FALSE(o.Check().ok());
}

}  // namespace
}  // namespace casual3d::depth
