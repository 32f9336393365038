#include "format/color_atlas.h"

#include <cstring>

namespace casual3d {

Image8 BuildColorAtlas(const TwoLayerPanorama& pano, int channels) {
  const int w = pano.width(), h = pano.height();
  if ((channels != 3 && channels != 4) || w < 1 || h < 1) return Image8();
  Image8 atlas(w, 2 * h, channels, 0);
  for (int layer = 0; layer < kNumLayers; ++layer) {
    const LayerData& own = pano.layer(layer);
    const LayerData& other = pano.layer(1 - layer);
    for (int y = 0; y < h; ++y) {
      uint8_t* out = atlas.row(y + layer * h);
      for (int x = 0; x < w; ++x) {
        const size_t i = pano.index(x, y);
        const LayerData* src = own.present[i] ? &own : other.present[i] ? &other : nullptr;
        if (src) std::memcpy(out + channels * x, &src->rgb[3 * i], 3);
        if (channels == 4) out[4 * x + 3] = 255;
      }
    }
  }
  return atlas;
}

}  // namespace casual3d
