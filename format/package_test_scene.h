#pragma once

// A procedural two-layer panorama for tests and benchmarks of the format, the
// package and the master file: a smooth background sphere with a sky cap
// (unlit), a near disc-shaped object in front of it, and a back layer that
// holds the background behind the object and a ring around it. Links follow
// depth continuity (ratio below 5%), same layer first, and are always mutual,
// so the result passes TwoLayerPanorama::Validate(). Header-only; not part of
// any library.

#include <cmath>
#include <cstdint>

#include "format/equirect.h"
#include "format/two_layer.h"

namespace casual3d::testing {

inline TwoLayerPanorama MakePackageTestPanorama(int width, int height, uint32_t seed = 1) {
  TwoLayerPanorama pano(width, height);
  auto hash = [seed](uint32_t x, uint32_t y, uint32_t c) {
    uint32_t h = seed * 0x9E3779B1u ^ x * 0x85EBCA6Bu ^ y * 0xC2B2AE35u ^ c * 0x27D4EB2Fu;
    h ^= h >> 15;
    h *= 0x2C1B3C6Du;
    h ^= h >> 12;
    return h;
  };
  const double object_radius = 0.45, ring_radius = 0.6;  // Angular radii (rad).
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double lon = ((x + 0.5) / width - 0.5) * 2.0 * kPi;
      const double lat = (0.5 - (y + 0.5) / height) * kPi;
      const Vec3d dir = LonLatToDirection(lon, lat);
      const double r = std::sqrt(lon * lon + lat * lat);
      const bool sky = lat > 1.1;
      const size_t i = pano.index(x, y);
      auto fill = [&](int l, bool object) {
        LayerData& L = pano.layer(l);
        L.present[i] = 1;
        L.label[i] = static_cast<uint8_t>(l == kFront ? NodeLabel::kF : NodeLabel::kB);
        double depth, nx = -dir.x, ny = -dir.y, nz = -dir.z;
        double cr, cg, cb;
        if (object) {
          depth = 2.0 + 0.4 * r;
          nx += 0.2 * std::sin(lon * 5.0);
          cr = 200 + 40 * std::sin(lon * 9.0);
          cg = 60 + 40 * std::cos(lat * 7.0);
          cb = 40;
        } else if (sky) {
          depth = 100.0;
          nx = ny = nz = 0.0;
          cr = 120 + 40 * lat;
          cg = 170 + 30 * lat;
          cb = 230;
        } else {
          depth = 8.0 + 2.0 * std::sin(3.0 * lon) * std::cos(lat);
          ny += 0.3 * std::cos(lon * 2.0);
          const bool check = ((static_cast<int>(std::floor(lon * 8)) +
                               static_cast<int>(std::floor(lat * 8))) & 1) != 0;
          const double shade = check ? 40 : 0;  // A luminance pattern, as most texture is.
          cr = 90 + shade + 30 * std::sin(lat * 4.0);
          cg = 110 + shade + 50 * std::cos(lon * 3.0);
          cb = 70 + shade;
        }
        // A little per-pixel texture, as real photographs have.
        const double noise = static_cast<double>(hash(x, y, l) % 7) - 3.0;
        const double rgb[3] = {cr + noise, cg + noise, cb + noise};
        for (int c = 0; c < 3; ++c)
          L.rgb[3 * i + c] =
              static_cast<uint8_t>(std::lround(std::fmin(255.0, std::fmax(0.0, rgb[c]))));
        L.depth_m[i] = static_cast<float>(depth);
        const double n = std::sqrt(nx * nx + ny * ny + nz * nz);
        if (n > 0) {
          L.normal[3 * i + 0] = static_cast<float>(nx / n);
          L.normal[3 * i + 1] = static_cast<float>(ny / n);
          L.normal[3 * i + 2] = static_cast<float>(nz / n);
        }
      };
      fill(kFront, r < object_radius);
      if (r < ring_radius) fill(kBack, false);
    }
  }
  // Links by depth continuity, same layer first so that the back layer joins the
  // front background where it emerges from behind the object.
  auto continuous = [](float a, float b) {
    return std::fabs(a - b) < 0.05f * std::fmin(a, b);
  };
  for (int pass = 0; pass < 2; ++pass) {
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        for (int d = 0; d < 2; ++d) {  // Right and down; the reverse links mirror them.
          const Direction dir = static_cast<Direction>(d);
          int nx, ny;
          if (!pano.Neighbour(x, y, dir, &nx, &ny)) continue;
          if (nx == x && ny == y) continue;
          const size_t p = pano.index(x, y), q = pano.index(nx, ny);
          for (int a = 0; a < kNumLayers; ++a) {
            for (int b = 0; b < kNumLayers; ++b) {
              if ((pass == 0) != (a == b)) continue;
              LayerData& A = pano.layer(a);
              LayerData& B = pano.layer(b);
              if (!A.present[p] || !B.present[q]) continue;
              if (GetLink(A.links[p], dir) != Link::kNone) continue;
              if (GetLink(B.links[q], Opposite(dir)) != Link::kNone) continue;
              if (!continuous(A.depth_m[p], B.depth_m[q])) continue;
              A.links[p] = SetLink(A.links[p], dir, b == kFront ? Link::kFront : Link::kBack);
              B.links[q] =
                  SetLink(B.links[q], Opposite(dir), a == kFront ? Link::kFront : Link::kBack);
            }
          }
        }
      }
    }
  }
  pano.frame().centre[0] = 0.25;
  pano.frame().centre[1] = -1.5;
  pano.frame().centre[2] = 3.0;
  return pano;
}

}  // namespace casual3d::testing
