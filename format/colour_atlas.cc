#include "format/colour_atlas.h"

#include <cstring>

#include "format/parallel.h"

namespace casual3d {

Image8 BuildColourAtlas(const TwoLayerPanorama& pano, int channels, int num_threads) {
  const int w = pano.width(), h = pano.height();
  if ((channels != 3 && channels != 4) || w < 1 || h < 1) return Image8();
  Image8 atlas(w, 2 * h, channels, 0);
  // Rows of both halves, independent of each other.
  ParallelFor(0, 2 * static_cast<int64_t>(h), ResolveThreads(num_threads), [&](int64_t row) {
    const int layer = row < h ? 0 : 1;
    const int y = static_cast<int>(row - static_cast<int64_t>(layer) * h);
    const LayerData& own = pano.layer(layer);
    const LayerData& other = pano.layer(1 - layer);
    uint8_t* out = atlas.row(static_cast<int>(row));
    for (int x = 0; x < w; ++x) {
      const size_t i = pano.index(x, y);
      const LayerData* src = own.present[i] ? &own : other.present[i] ? &other : nullptr;
      if (src) std::memcpy(out + channels * x, &src->rgb[3 * i], 3);
      if (channels == 4) out[4 * x + 3] = 255;
    }
  }, 32);
  return atlas;
}

}  // namespace casual3d
