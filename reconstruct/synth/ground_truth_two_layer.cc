#include "reconstruct/synth/ground_truth_two_layer.h"

#include <algorithm>
#include <cmath>

#include "reconstruct/synth/srgb.h"

namespace casual3d::synth {
namespace {

double Ratio(float a, float b) { return std::min(a, b) / std::max(a, b); }

}  // namespace

TwoLayerPanorama GroundTruthToTwoLayer(const GroundTruthPanorama& gt, const TwoLayerOptions& options) {
  const int w = gt.pixels.width(), h = gt.pixels.height();
  TwoLayerPanorama pano(w, h);
  pano.frame() = gt.frame;

  double far_m = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int ch : {kFrontZ, kBackZ}) {
        const float z = gt.pixels.at(x, y, ch);
        if (std::isfinite(z)) far_m = std::max(far_m, static_cast<double>(z));
      }
  const float sky_m = static_cast<float>(std::max(options.sky_depth_m, 2.0 * far_m));

  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = pano.index(x, y);
      const float front_z = gt.pixels.at(x, y, kFrontZ);
      for (int l = 0; l < kNumLayers; ++l) {
        const int base = l == kFront ? kFrontR : kBackR;
        const float z = gt.pixels.at(x, y, base + (kFrontZ - kFrontR));
        if (std::isnan(z) || !(z > 0)) continue;  // No surface.
        const float depth = std::isinf(z) ? sky_m : z;
        if (l == kBack) {
          const float front_depth = std::isinf(front_z) ? sky_m : front_z;
          if (front_depth / depth > options.tau_dratio) continue;  // Redundant (Sec. 4.4.3 step 1).
        }
        LayerData& layer = pano.layer(l);
        layer.present[i] = 1;
        layer.depth_m[i] = depth;
        for (int k = 0; k < 3; ++k) {
          layer.rgb[3 * i + k] = LinearToSrgb8(gt.pixels.at(x, y, base + k));
          layer.normal[3 * i + k] =
              std::isinf(z) ? 0.0f : gt.pixels.at(x, y, base + (kFrontNX - kFrontR) + k);
        }
        layer.label[i] = static_cast<uint8_t>(l == kFront ? NodeLabel::kF : NodeLabel::kB);
      }
    }
  }

  // Links between each pixel and its right and down neighbours (the other two
  // directions are the mutual halves).
  const float ratio_min = static_cast<float>(options.link_ratio);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (Direction dir : {kRight, kDown}) {
        int nx, ny;
        if (!pano.Neighbour(x, y, dir, &nx, &ny)) continue;
        const size_t p = pano.index(x, y), q = pano.index(nx, ny);
        struct Pair {
          int a, b;
          double ratio;
        };
        Pair pairs[4];
        int count = 0;
        for (int a = 0; a < kNumLayers; ++a) {
          if (!pano.layer(a).present[p]) continue;
          for (int b = 0; b < kNumLayers; ++b) {
            if (!pano.layer(b).present[q]) continue;
            const double r = Ratio(pano.layer(a).depth_m[p], pano.layer(b).depth_m[q]);
            if (r > ratio_min) pairs[count++] = {a, b, r};
          }
        }
        std::sort(pairs, pairs + count, [](const Pair& s, const Pair& t) {
          return s.ratio > t.ratio || (s.ratio == t.ratio && (s.a < t.a || (s.a == t.a && s.b < t.b)));
        });
        bool used_p[kNumLayers] = {false, false}, used_q[kNumLayers] = {false, false};
        int linked_a = -1, linked_b = -1;
        for (int k = 0; k < count; ++k) {
          const Pair& pr = pairs[k];
          if (used_p[pr.a] || used_q[pr.b]) continue;
          if (linked_a >= 0) {
            // A second link must keep the depth order on both sides (no crossing).
            const bool order_p = pano.layer(linked_a).depth_m[p] < pano.layer(pr.a).depth_m[p];
            const bool order_q = pano.layer(linked_b).depth_m[q] < pano.layer(pr.b).depth_m[q];
            if (order_p != order_q) continue;
          }
          used_p[pr.a] = used_q[pr.b] = true;
          linked_a = pr.a;
          linked_b = pr.b;
          uint8_t& lp = pano.layer(pr.a).links[p];
          uint8_t& lq = pano.layer(pr.b).links[q];
          lp = SetLink(lp, dir, pr.b == kFront ? Link::kFront : Link::kBack);
          lq = SetLink(lq, Opposite(dir), pr.a == kFront ? Link::kFront : Link::kBack);
        }
      }
    }
  }
  return pano;
}

}  // namespace casual3d::synth
