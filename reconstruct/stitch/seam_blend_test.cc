#include "reconstruct/stitch/seam_blend.h"

#include <algorithm>
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>

namespace casual3d::stitch {
namespace {

Image<int16_t> Labels(int w, int h) { return Image<int16_t>(w, h, 1, -1); }

void ExpectWindow(const Image<int16_t>& label, int x0, int y0, int width, int height, bool wrap) {
  SeamWindow win;
  ASSERT_TRUE(FindSeamWindow(label, &win));
  EXPECT_EQ(win.x0, x0);
  EXPECT_EQ(win.width, width);
  EXPECT_EQ(win.wrap, wrap);
  EXPECT_EQ(win.y0, y0);
  EXPECT_EQ(win.height, height);
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

// A band all round the panorama, so that its columns wrap: photo 0 at level
// 100 everywhere, photo 1 at 140 on the right half only, one surface 2 m
// away. The blend is photo 0 alone on the left and the mean, 120, on the
// right: jumps of 20 at the middle and across the wrap. The seam blend
// evens both out and leaves the halves' middles (8 fading lengths away) as
// they were.
TEST(BlendSeamsTest, JumpsFadeAcrossTheWrap) {
  const int W = 256, H = 128, y0 = 40, h = 48;
  auto photo = [&](uint8_t level, int from) {
    warp::WarpedView v;
    v.front.y0 = y0;
    v.front.rgb = Image8(W, h, 3, level);
    v.front.depth_m = ImageF(W, h, 1, 0.0f);
    v.front.stretch = ImageF(W, h, 1, 0.0f);
    for (int y = 0; y < h; ++y)
      for (int x = from; x < W; ++x) v.front.depth_m.at(x, y) = 2.0f;
    return v;
  };
  const std::vector<warp::WarpedView> full = {photo(100, 0), photo(140, W / 2)};
  const FullWarps warps{false, full, W, 0.02};
  StitchOptions options;
  StitchedLayer layer;
  layer.rgb = Image8(W, H, 3, 0);
  layer.depth_m = ImageF(W, H, 1, 0.0f);
  layer.label = Image<int16_t>(W, H, 1, -1);
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = 0; x < W; ++x) {
      layer.label.at(x, y) = 0;
      layer.depth_m.at(x, y) = 2.0f;
      for (int c = 0; c < 3; ++c) layer.rgb.at(x, y, c) = x < W / 2 ? 100 : 120;
    }
  }
  Image<uint64_t> keys(W, H, 1, 0);  // As the stitch records them.
  std::vector<std::pair<int, double>> members;
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = 0; x < W; ++x) {
      BlendMembers(warps, 0, x, y, 0.0f, options, &members);
      keys.at(x, y) = BlendKey(members);
    }
  }
  BlendSeams(warps, nullptr, options, keys, &layer);
  EXPECT_GT(layer.seam_blend.pairs_with_target, 0);
  for (int y = y0; y < y0 + h; ++y) {
    int largest = 0;
    for (int x = 0; x < W; ++x) {
      const int next = (x + 1) % W;  // The last column's step is across the wrap.
      largest = std::max(largest, std::abs(layer.rgb.at(next, y, 0) - layer.rgb.at(x, y, 0)));
    }
    EXPECT_LE(largest, 2) << "row " << y;
    EXPECT_NEAR(layer.rgb.at(W / 4, y, 1), 100, 1);
    EXPECT_NEAR(layer.rgb.at(3 * W / 4, y, 2), 120, 1);
    EXPECT_NEAR(layer.rgb.at(W / 2, y, 0), 110, 3);
    EXPECT_NEAR(layer.rgb.at(0, y, 0), 110, 3);
  }
}

}  // namespace
}  // namespace casual3d::stitch
