#include "reconstruct/depth/label_histogram.h"

#include <gtest/gtest.h>

#include <vector>

namespace casual3d::depth {
namespace {

TEST(LabelHistogram, WeightedMedianOverRowsWithRunsAndGaps) {
  std::vector<float> bins(10, 0.0f);
  LabelHistogram h(bins.data());
  // Label 2 weighs 1.5, label 5 weighs 2.0, label 7 weighs 1.0; -1 is no label.
  const int row0[] = {2, 2, 2, -1, 5, 5};
  const float w0[] = {0.5f, 0.5f, 0.5f, 9.0f, 0.5f, 0.5f};
  const int row1[] = {5, 5, 7, 7};
  const float w1[] = {0.5f, 0.5f, 0.5f, 0.5f};
  h.AddRow(row0, w0, 6);
  h.AddRow(row1, w1, 4);
  // Total 4.5: cumulative 1.5 at 2, 3.5 at 5 >= 2.25.
  EXPECT_EQ(h.MedianAndClear(4.5f), 5);
  for (float b : bins) EXPECT_EQ(b, 0.0f);
  // Reused after clearing: label 2 alone now holds the majority.
  const float w2[] = {3.0f, 0.0f, 0.0f, 0.0f, 0.5f, 0.5f};
  h.AddRow(row0, w2, 6);
  EXPECT_EQ(h.MedianAndClear(4.0f), 2);
  for (float b : bins) EXPECT_EQ(b, 0.0f);
}

TEST(LabelHistogram, EmptyAndShortTotals) {
  std::vector<float> bins(4, 0.0f);
  LabelHistogram h(bins.data());
  EXPECT_EQ(h.MedianAndClear(0.0f), -1);
  const int none[] = {-1, -1};
  const float w[] = {1.0f, 1.0f};
  h.AddRow(none, w, 2);
  EXPECT_EQ(h.MedianAndClear(2.0f), -1);
  // A total the bins fall short of (rounding): the greatest label added.
  const int some[] = {1, 3};
  h.AddRow(some, w, 2);
  EXPECT_EQ(h.MedianAndClear(5.0f), 3);
  for (float b : bins) EXPECT_EQ(b, 0.0f);
}

}  // namespace
}  // namespace casual3d::depth
