#include "reconstruct/stitch/seam_blend.h"

#include <gtest/gtest.h>

namespace casual3d::stitch {
namespace {

Image<int16_t> Labels(int w, int h) { return Image<int16_t>(w, h, 1, -1); }

TEST(SeamWindowTest, NoLabelNoWindow) {
  SeamWindow win;
  EXPECT_FALSE(FindSeamWindow(Labels(16, 8), &win));
}

TEST(SeamWindowTest, LabelsAllRoundWrap) {
  Image<int16_t> label = Labels(16, 8);
  for (int x = 0; x < 16; ++x) label.at(x, 3 + x % 2) = 0;
  SeamWindow win;
  ASSERT_TRUE(FindSeamWindow(label, &win));
  EXPECT_EQ(win.x0, 0);
  EXPECT_EQ(win.width, 16);
  EXPECT_TRUE(win.wrap);
  EXPECT_EQ(win.y0, 3);
  EXPECT_EQ(win.height, 2);
}

// Content across column 0 (the seam at +-180 degrees): the window starts
// after the longest empty run and goes round, without wrapping.
TEST(SeamWindowTest, ContentAcrossColumnZero) {
  Image<int16_t> label = Labels(32, 4);
  for (int x : {28, 29, 31, 0, 1, 2}) label.at(x, 1) = 2;  // Column 30 empty: a shorter gap.
  label.at(10, 2) = 1;                                       // Gaps 3-9 (7) and 11-27 (17).
  SeamWindow win;
  ASSERT_TRUE(FindSeamWindow(label, &win));
  EXPECT_EQ(win.x0, 28);
  EXPECT_EQ(win.width, 32 - 17);
  EXPECT_FALSE(win.wrap);
  EXPECT_EQ(win.y0, 1);
  EXPECT_EQ(win.height, 2);
}

TEST(SeamWindowTest, OneColumn) {
  Image<int16_t> label = Labels(8, 5);
  label.at(7, 4) = 0;
  SeamWindow win;
  ASSERT_TRUE(FindSeamWindow(label, &win));
  EXPECT_EQ(win.x0, 7);
  EXPECT_EQ(win.width, 1);
  EXPECT_FALSE(win.wrap);
  EXPECT_EQ(win.y0, 4);
  EXPECT_EQ(win.height, 1);
}

}  // namespace
}  // namespace casual3d::stitch
