#include "reconstruct/depth/flat_region_steps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace casual3d::depth::flat {
namespace {

constexpr float kGrey = 0.5f;

// A grey wall of w x h pixels (flat: w_photo 0) crossed by a dark textured
// pole of `pole` columns from x = x0 (w_photo 1).
void WallWithPole(int w, int h, int x0, int pole, ImageF* color, ImageF* weight) {
  *color = ImageF(w, h, 3, kGrey);
  *weight = ImageF(w, h, 1, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = x0; x < x0 + pole; ++x) {
      for (int c = 0; c < 3; ++c) color->at(x, y, c) = 0.1f;
      weight->at(x, y) = 1.0f;
    }
}

TEST(SegmentFlatGroups, JoinsTheWallThatAThinPoleCrosses) {
  ImageF color, weight;
  WallWithPole(60, 40, 29, 3, &color, &weight);
  const FlatGroups groups = SegmentFlatGroups(color, weight, FlatRegionOptions());
  const int left = groups.group[5 * 60 + 5], right = groups.group[5 * 60 + 50];
  ASSERT_GE(left, 0);
  EXPECT_EQ(left, right);
  EXPECT_EQ(groups.group[5 * 60 + 30], -1);  // The pole.
  EXPECT_EQ(groups.area[left], 57 * 40);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(groups.color[left][c], kGrey, 1e-6);
}

TEST(SegmentFlatGroups, KeepsTheSidesApartAcrossAWidePoleAndDropsSmallRegions) {
  ImageF color, weight;
  WallWithPole(60, 40, 29, 3, &color, &weight);
  // A 4 x 4 patch of another colour: below min_region_pixels (30).
  for (int y = 10; y < 14; ++y)
    for (int x = 10; x < 14; ++x) color.at(x, y, 0) = 0.9f;
  FlatRegionOptions options;
  options.merge_gap = 2;  // Narrower than the pole.
  const FlatGroups groups = SegmentFlatGroups(color, weight, options);
  const int left = groups.group[5 * 60 + 5], right = groups.group[5 * 60 + 50];
  ASSERT_GE(left, 0);
  ASSERT_GE(right, 0);
  EXPECT_NE(left, right);
  EXPECT_EQ(groups.group[11 * 60 + 11], -1);
}

TEST(SegmentFlatGroups, TexturedImageHasNoGroups) {
  ImageF color(20, 10, 3, kGrey), weight(20, 10, 1, 1.0f);
  EXPECT_EQ(SegmentFlatGroups(color, weight, FlatRegionOptions()).size(), 0);
}

// Two groups of the same colour, x < 8 and x >= 12 of a 20 x 10 image;
// group 0 has the plane label = 5.
struct TwoGroups {
  FlatGroups groups;
  std::vector<PlaneFit> fits;
  std::vector<std::vector<EdgePoint>> measured;
  TwoGroups() {
    groups.group.assign(200, -1);
    for (int y = 0; y < 10; ++y)
      for (int x = 0; x < 20; ++x)
        if (x < 8 || x >= 12) groups.group[y * 20 + x] = x < 8 ? 0 : 1;
    groups.area = {80, 80};
    groups.color = {{{kGrey, kGrey, kGrey}}, {{kGrey, kGrey, kGrey}}};
    fits.resize(2);
    fits[0].ok = true;
    fits[0].plane.c = 5;
    measured.resize(2);
  }
  void Adopt(const FlatRegionOptions& options) {
    AdoptPlanes(groups, 20, 10, measured, {0}, {1}, options, &fits);
  }
};

TEST(AdoptPlanes, TakesTheCloseSameColoredGroupsPlane) {
  TwoGroups t;
  EdgePoint e;
  e.x = 15;
  e.y = 3;
  e.label = 5.5f;  // Touches the plane.
  t.measured[1].push_back(e);
  t.Adopt(FlatRegionOptions());
  EXPECT_TRUE(t.fits[1].ok);
  EXPECT_EQ(t.fits[1].plane.c, 5);
}

TEST(AdoptPlanes, RefusesAFarOtherColoredOrContradictedPlane) {
  FlatRegionOptions near;
  near.adopt_distance = 4;  // The boxes are 5 pixels apart.
  TwoGroups far;
  far.Adopt(near);
  EXPECT_FALSE(far.fits[1].ok);

  TwoGroups other;
  other.groups.color[1] = {0.5f, 0.7f, 0.5f};
  other.Adopt(FlatRegionOptions());
  EXPECT_FALSE(other.fits[1].ok);

  TwoGroups behind;  // Its edge is 4 labels farther than the plane.
  EdgePoint e;
  e.label = 9;
  behind.measured[1].push_back(e);
  behind.Adopt(FlatRegionOptions());
  EXPECT_FALSE(behind.fits[1].ok);
}

TEST(AssignPriors, CoversTheGroupAndItsConnectedColorClampedToTheLabels) {
  const int w = 10, h = 4, labels = 5;
  ImageF color(w, h, 3, kGrey), weight(w, h, 1, 0.0f);
  FlatGroups groups;
  groups.group.assign(w * h, -1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (x < 5) groups.group[y * w + x] = 0;
      else weight.at(x, y) = x < 8 ? 0.2f : 0.9f;  // Extended up to x = 7.
    }
  color.at(6, 0, 1) = 0.9f;  // Another colour.
  groups.area = {5 * h};
  groups.color = {{{kGrey, kGrey, kGrey}}};
  std::vector<PlaneFit> fits(1);
  fits[0].ok = true;
  fits[0].plane.a = 1;
  fits[0].plane.c = -1;  // label = x - 1.
  FlatRegionStats stats;
  const std::vector<float> prior =
      AssignPriors(color, weight, groups, fits, labels, FlatRegionOptions(), &stats);
  EXPECT_EQ(prior[1 * w + 0], 0.0f);  // -1, clamped.
  EXPECT_EQ(prior[1 * w + 3], 2.0f);
  EXPECT_EQ(prior[1 * w + 6], 4.0f);  // 5, clamped to labels - 1.
  EXPECT_TRUE(std::isnan(prior[1 * w + 8]));
  EXPECT_TRUE(std::isnan(prior[0 * w + 6]));
  EXPECT_EQ(stats.fitted, 1);
  EXPECT_EQ(stats.pixels, 5 * h + 3 * h - 1);
}

}  // namespace
}  // namespace casual3d::depth::flat
