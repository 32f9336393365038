#include "encoder/absent_fill.h"

#include <algorithm>
#include <cassert>
#include <vector>

namespace casual3d::encoder {

void FillAbsentCodes(const TwoLayerPanorama& pano, int x0, int y0, int w, int h, Image8* image) {
  assert(image->height() == 2 * h && image->width() % w == 0);
  const int c = image->channels();
  // Each part of w columns holds codes of the tile's nodes (one part, or two
  // for lossy normals), filled alike.
  for (int part = 0; part < image->width() / w; ++part) {
    auto at = [&](int x, int y) { return &image->at(part * w + x, y); };
    for (int l = 0; l < kNumLayers; ++l) {
      const LayerData& L = pano.layer(l);
      std::vector<uint8_t> column_filled(w, 0);
      // Columns: down from each present node; above the first, up from it. A
      // column then repeats codes, which the lossless coder's "top" predictor
      // and backward references code in almost nothing.
      for (int x = 0; x < w; ++x) {
        int last = -1;
        for (int y = 0; y < h; ++y) {
          uint8_t* px = at(x, l * h + y);
          if (L.present[pano.index(x0 + x, y0 + y)]) {
            for (int yy = last < 0 ? 0 : y; yy < y; ++yy) std::copy_n(px, c, at(x, l * h + yy));
            last = y;
          } else if (last >= 0) {
            std::copy_n(at(x, l * h + last), c, px);
          }
        }
        column_filled[x] = last >= 0;
      }
      // Columns without nodes: a copy of the nearest filled column on the
      // left, then, before the first filled column, of the first one.
      int first = -1;
      for (int x = 0; x < w; ++x) {
        if (column_filled[x]) {
          if (first < 0) first = x;
          continue;
        }
        if (first < 0) continue;
        for (int y = 0; y < h; ++y) std::copy_n(at(x - 1, l * h + y), c, at(x, l * h + y));
      }
      if (first <= 0) continue;  // No node in this half, or column 0 has one.
      for (int x = 0; x < first; ++x)
        for (int y = 0; y < h; ++y) std::copy_n(at(first, l * h + y), c, at(x, l * h + y));
    }
  }
}

}  // namespace casual3d::encoder
