#include "reconstruct/depth/edge_median.h"

#include <gtest/gtest.h>

namespace casual3d::depth {
namespace {

// A near object (colour 0.2, label 50) left of x = 20 in front of a
// background (colour 0.8, label 10); the labelling is fattened: the near label
// reaches 3 pixels into the background, as a window-based cost leaves it.
TEST(EdgeAwareMedian, RemovesAFattenedBandAndSnapsTheEdgeToTheColorEdge) {
  const int w = 48, h = 24;
  ImageF color(w, h, 3);
  std::vector<int> labels(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) color.at(x, y, c) = x < 20 ? 0.2f : 0.8f;
      labels[static_cast<size_t>(y) * w + x] = x < 23 ? 50 : 10;
    }
  const std::vector<int> out = EdgeAwareMedian(labels, 64, color, EdgeMedianOptions());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      ASSERT_EQ(out[static_cast<size_t>(y) * w + x], x < 20 ? 50 : 10) << x << "," << y;
}

TEST(EdgeAwareMedian, KeepsThinStructuresOfTheirOwnColor) {
  // A 2-pixel-wide pole (own colour, own label) survives the filter.
  const int w = 40, h = 30;
  ImageF color(w, h, 3);
  std::vector<int> labels(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool pole = x == 20 || x == 21;
      for (int c = 0; c < 3; ++c) color.at(x, y, c) = pole ? 0.9f : 0.4f;
      labels[static_cast<size_t>(y) * w + x] = pole ? 100 : 5;
    }
  const std::vector<int> out = EdgeAwareMedian(labels, 128, color, EdgeMedianOptions());
  EXPECT_EQ(out, labels);
}

TEST(EdgeAwareMedian, RadiusZeroIsTheIdentityAndSizesAreChecked) {
  ImageF color(5, 4, 3, 0.5f);
  std::vector<int> labels(20, 3);
  labels[7] = 9;
  EdgeMedianOptions o;
  o.radius = 0;
  EXPECT_EQ(EdgeAwareMedian(labels, 10, color, o), labels);
  EXPECT_THROW(EdgeAwareMedian(std::vector<int>(19, 0), 10, color, EdgeMedianOptions()),
               std::invalid_argument);
  o.radius = 40;
  EXPECT_THROW(EdgeAwareMedian(labels, 10, color, o), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth
