#include "encoder/level_of_detail.h"

#include <cmath>
#include <string>

namespace casual3d::encoder {

StatusOr<TwoLayerPanorama> HalvePanorama(const TwoLayerPanorama& fine) {
  if (fine.width() % 2 != 0 || fine.height() % 2 != 0 || fine.width() < 2 || fine.height() < 2)
    return InvalidArgument("cannot halve a " + std::to_string(fine.width()) + "x" +
                           std::to_string(fine.height()) +
                           " panorama: width and height must be even");
  const int w = fine.width() / 2, h = fine.height() / 2;
  TwoLayerPanorama coarse(w, h);
  coarse.frame() = fine.frame();
  coarse.view_hints() = fine.view_hints();
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& F = fine.layer(l);
    LayerData& C = coarse.layer(l);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const size_t a = fine.index(2 * x, 2 * y);
        if (!F.present[a]) continue;
        const size_t c = coarse.index(x, y);
        C.present[c] = 1;
        C.depth_m[c] = F.depth_m[a];
        C.label[c] = F.label[a];
        // Colour and normal: box filters over the block's nodes on the same
        // surface (a normal only where the node's is lit: unlit stays unlit).
        int sum[3] = {0, 0, 0}, count = 0;
        double normal[3] = {0, 0, 0};
        const bool lit = F.normal[3 * a] != 0 || F.normal[3 * a + 1] != 0 || F.normal[3 * a + 2] != 0;
        for (int dy = 0; dy < 2; ++dy) {
          for (int dx = 0; dx < 2; ++dx) {
            const size_t b = fine.index(2 * x + dx, 2 * y + dy);
            if (!F.present[b] || std::fabs(F.depth_m[b] - F.depth_m[a]) > 0.05f * F.depth_m[a])
              continue;
            for (int k = 0; k < 3; ++k) sum[k] += F.rgb[3 * b + k];
            for (int k = 0; k < 3; ++k) normal[k] += F.normal[3 * b + k];
            ++count;
          }
        }
        for (int k = 0; k < 3; ++k)
          C.rgb[3 * c + k] = static_cast<uint8_t>((sum[k] + count / 2) / count);
        const double length =
            std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
        for (int k = 0; k < 3; ++k)
          C.normal[3 * c + k] = lit && length > 1e-6 ? static_cast<float>(normal[k] / length)
                                                     : F.normal[3 * a + k];
        // Links: two steps along the fine graph.
        uint8_t links = 0;
        for (int d = 0; d < kNumDirections; ++d) {
          const Direction dir = static_cast<Direction>(d);
          int cx, cy;
          if (!coarse.Neighbour(x, y, dir, &cx, &cy)) continue;
          int px = 2 * x, py = 2 * y, layer = l;
          bool ok = true;
          for (int step = 0; step < 2 && ok; ++step) {
            const Link link = GetLink(fine.layer(layer).links[fine.index(px, py)], dir);
            int nx, ny;
            if (link == Link::kNone || !fine.Neighbour(px, py, dir, &nx, &ny)) {
              ok = false;
              break;
            }
            px = nx;
            py = ny;
            layer = link == Link::kFront ? kFront : kBack;
          }
          if (ok) links = SetLink(links, dir, layer == kFront ? Link::kFront : Link::kBack);
        }
        C.links[c] = links;
      }
    }
  }
  return coarse;
}

}  // namespace casual3d::encoder
