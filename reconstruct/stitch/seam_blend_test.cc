#include "reconstruct/stitch/seam_blend.h"

#include <gtest/gtest.h>

namespace casual3d::stitch {
namespace {

Image<int16_t> Labels(int w, int h) { return Image<int16_t>(w, h, 1, -1); }

void ExpectWindow(const Image<int16_t>& label, int x0, int y0, int width, int height, bool wrap) {
  SeamWindow want;
  want.x0 = x0;
  want.y0 = y0;
  want.width = width;
  want.height = height;
  want.wrap = wrap;
  SeamWindow win;
  ASSERT_TRUE(FindSeamWindow(label, &win));
  EXPECT_EQ(win.x0, want.x0);
  EXPECT_EQ(win.width, want.width);
  EXPECT_EQ(win.wrap, want.wrap);
  EXPECT_EQ(win.y0, want.y0);
  EXPECT_EQ(win.height, want.height);
}

TEST(SeamWindowTest, NoLabelNoWindow) {
  SeamWindow win;
  EXPECT_FALSE(FindSeamWindow(Labels(16, 8), &win));
}

TEST(SeamWindowTest, LabelsAllRoundWrap) {
  Image<int16_t> label = Labels(16, 8);
  for (int x = 0; x < 16; ++x) label.at(x, 3 + x % 2) = 0;
  ExpectWindow(label, /*x0=*/0, /*y0=*/3, /*width=*/16, /*height=*/2, /*wrap=*/true);
}

// Content across column 0 (the seam at +-180 degrees): the window starts
// after the longest empty run and goes round, without wrapping.
TEST(SeamWindowTest, ContentAcrossColumnZero) {
  Image<int16_t> label = Labels(32, 4);
  for (int x : {28, 29, 31, 0, 1, 2}) label.at(x, 1) = 2;  // Column 30 empty: a shorter gap.
  label.at(10, 2) = 1;                                       // Gaps 3-9 (7) and 11-27 (17).
  ExpectWindow(label, /*x0=*/28, /*y0=*/1, /*width=*/32 - 17, /*height=*/2, /*wrap=*/false);
}

TEST(SeamWindowTest, OneColumn) {
  Image<int16_t> label = Labels(8, 5);
  label.at(7, 4) = 0;
  ExpectWindow(label, /*x0=*/7, /*y0=*/4, /*width=*/1, /*height=*/1, /*wrap=*/false);
}

}  // namespace
}  // namespace casual3d::stitch
