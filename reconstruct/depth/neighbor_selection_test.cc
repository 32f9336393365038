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

}  // namespace
}  // namespace casual3d::depth
