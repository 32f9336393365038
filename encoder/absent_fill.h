#pragma once

// Values at absent nodes of the lossless data images (spec/package.md Sec. 4.2,
// 4.3 and 5: readers ignore the depth and normal codes of absent nodes, so a
// writer may put any value there). Zeros cost a lossless coder a large
// residual at every edge between a present and an absent node; copying codes
// of present nodes into the gaps makes those residuals small.

#include "format/image.h"
#include "format/two_layer.h"

namespace casual3d::encoder {

// Fills the pixels of absent nodes of a depth or normal tile image `image`
// (w x 2h, 3 channels: rows [0, h) the front layer and [h, 2h) the back layer,
// as EncodeTileImage writes it; for lossy normals 2w x 2h, 4 channels, each
// half of w columns filled alike) of the tile at (x0, y0) of `pano`. In each
// column of each layer half, an absent node takes the code of the nearest
// present node above it in the tile, or, above the column's first present
// node, that node's code; a column without present nodes takes the filled
// column on its left (or, left of the first such column, the one on its
// right); a half without present nodes stays zero. Present nodes are left
// unchanged, and every filled value is the code of a present node, so it is
// valid wherever a reader would look (readers before spec 1.1 revision 2
// checked the codes of absent nodes too).
void FillAbsentCodes(const TwoLayerPanorama& pano, int x0, int y0, int w, int h, Image8* image);

}  // namespace casual3d::encoder
