#include "encoder/absent_fill.h"

#include <gtest/gtest.h>

#include "format/tile_codec.h"

namespace casual3d::encoder {
namespace {

// A 4x3 tile image (one layer half of 3 rows) whose present nodes carry code
// (10 * x + y + 1, 100 + x) in R, G.
TEST(FillAbsentCodesTest, ColumnsDownThenUpThenSideways) {
  TwoLayerPanorama pano(6, 3);
  // Front, tile columns 0..3 = panorama columns 1..4: column 0 has a node at
  // row 1, column 1 none, column 2 nodes at rows 0 and 2, column 3 none. The
  // back layer has no node.
  const int x0 = 1;
  const int present[][2] = {{0, 1}, {2, 0}, {2, 2}};
  Image8 image(4, 6, 3, 0);
  for (const auto& p : present) {
    pano.layer(kFront).present[pano.index(x0 + p[0], p[1])] = 1;
    image.at(p[0], p[1], 0) = static_cast<uint8_t>(10 * p[0] + p[1] + 1);
    image.at(p[0], p[1], 1) = static_cast<uint8_t>(100 + p[0]);
  }
  // A present node outside the tile must not leak in.
  pano.layer(kFront).present[pano.index(5, 1)] = 1;
  FillAbsentCodes(pano, x0, 0, 4, 3, &image);
  // Column 0: rows 0 (up from row 1) and 2 (down from row 1) take row 1's code.
  for (int y = 0; y < 3; ++y) {
    EXPECT_EQ(image.at(0, y, 0), 2) << y;
    EXPECT_EQ(image.at(0, y, 1), 100) << y;
  }
  // Column 2: row 1 takes row 0's code (down), row 2 keeps its own.
  EXPECT_EQ(image.at(2, 0, 0), 21);
  EXPECT_EQ(image.at(2, 1, 0), 21);
  EXPECT_EQ(image.at(2, 2, 0), 23);
  // Columns 1 and 3 have no node: copies of the column on their left.
  for (int y = 0; y < 3; ++y) {
    EXPECT_EQ(image.at(1, y, 0), image.at(0, y, 0)) << y;
    EXPECT_EQ(image.at(3, y, 0), image.at(2, y, 0)) << y;
    EXPECT_EQ(image.at(3, y, 1), 102) << y;
  }
  // B stays 0 (spec/package.md Sec. 4: writers write 0), the back half stays zero.
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 4; ++x) {
      EXPECT_EQ(image.at(x, y, 2), 0);
      if (y >= 3) EXPECT_EQ(image.at(x, y, 0) | image.at(x, y, 1), 0) << x << "," << y;
    }
}

TEST(FillAbsentCodesTest, LeadingEmptyColumnsCopyTheFirstFilledOne) {
  TwoLayerPanorama pano(3, 2);
  pano.layer(kBack).present[pano.index(2, 1)] = 1;
  Image8 image(3, 4, 3, 0);
  image.at(2, 3, 0) = 7;
  image.at(2, 3, 1) = 9;
  FillAbsentCodes(pano, 0, 0, 3, 2, &image);
  for (int y = 2; y < 4; ++y)
    for (int x = 0; x < 3; ++x) {
      EXPECT_EQ(image.at(x, y, 0), 7) << x << "," << y;
      EXPECT_EQ(image.at(x, y, 1), 9) << x << "," << y;
    }
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) EXPECT_EQ(image.at(x, y, 0), 0);  // Front half: no node.
}

}  // namespace
}  // namespace casual3d::encoder
