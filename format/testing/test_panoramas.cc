#include "format/testing/test_panoramas.h"

#include <algorithm>
#include <cmath>

#include "format/equirect.h"

namespace casual3d {
namespace testing {
namespace {

constexpr double kBoxMin[3] = {-2.0, -1.5, -4.0};
constexpr double kBoxMax[3] = {3.0, 2.5, 2.5};

// Exit distance of the ray t*dir from the origin through the room box, and the
// inward wall normal there.
double HitBox(const Vec3d& dir, double normal[3], int* face) {
  const double d[3] = {dir.x, dir.y, dir.z};
  double best = 1e30;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) continue;
    const double bound = d[a] > 0 ? kBoxMax[a] : kBoxMin[a];
    const double t = bound / d[a];
    if (t < best) {
      best = t;
      normal[0] = normal[1] = normal[2] = 0.0;
      normal[a] = d[a] > 0 ? -1.0 : 1.0;
      *face = 2 * a + (d[a] > 0 ? 1 : 0);
    }
  }
  return best;
}

// Nearest positive distance to the sphere, or a negative value on a miss.
double HitSphere(const Vec3d& dir, const RoomOptions& o) {
  const double* c = o.sphere_centre;
  const double b = dir.x * c[0] + dir.y * c[1] + dir.z * c[2];
  const double cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
  const double disc = b * b - cc + o.sphere_radius_m * o.sphere_radius_m;
  if (disc < 0) return -1.0;
  const double t = b - std::sqrt(disc);
  return t > 0 ? t : -1.0;
}

void SetNode(TwoLayerPanorama* p, int l, int x, int y, float depth, const double n[3],
             const uint8_t rgb[3]) {
  LayerData& d = p->layer(l);
  const size_t i = p->index(x, y);
  d.present[i] = 1;
  d.depth_m[i] = depth;
  for (int c = 0; c < 3; ++c) {
    d.normal[3 * i + c] = static_cast<float>(n[c]);
    d.rgb[3 * i + c] = rgb[c];
  }
  d.label[i] = static_cast<uint8_t>(l == kFront ? NodeLabel::kF : NodeLabel::kB);
}

void RoomColor(const Vec3d& p, int face, uint8_t rgb[3]) {
  const int checker =
      (static_cast<int>(std::floor(p.x * 2.0)) + static_cast<int>(std::floor(p.y * 2.0)) +
       static_cast<int>(std::floor(p.z * 2.0))) &
      1;
  rgb[0] = static_cast<uint8_t>(60 + 30 * face + 40 * checker);
  rgb[1] = static_cast<uint8_t>(200 - 25 * face);
  rgb[2] = static_cast<uint8_t>(90 + 60 * checker);
}

}  // namespace

TwoLayerPanorama MakeRoomPanorama(int width, int height, const RoomOptions& options) {
  TwoLayerPanorama pano(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Vec3d dir = EquirectPixelToDirection(x + 0.5, y + 0.5, width, height);
      double wall_normal[3] = {0, 0, 0};
      int face = 0;
      const double t_room = HitBox(dir, wall_normal, &face);
      const Vec3d p_room = {dir.x * t_room, dir.y * t_room, dir.z * t_room};
      uint8_t room_rgb[3];
      RoomColor(p_room, face, room_rgb);
      const double t_sphere = options.with_sphere ? HitSphere(dir, options) : -1.0;
      if (t_sphere > 0 && t_sphere < t_room) {
        const double* c = options.sphere_centre;
        const double r = options.sphere_radius_m;
        const double n[3] = {(dir.x * t_sphere - c[0]) / r, (dir.y * t_sphere - c[1]) / r,
                             (dir.z * t_sphere - c[2]) / r};
        const uint8_t rgb[3] = {static_cast<uint8_t>(150 + 100 * std::max(0.0, n[1])), 40, 30};
        SetNode(&pano, kFront, x, y, static_cast<float>(t_sphere), n, rgb);
        if (options.with_back_layer) {
          SetNode(&pano, kBack, x, y, static_cast<float>(t_room), wall_normal, room_rgb);
        }
      } else {
        SetNode(&pano, kFront, x, y, static_cast<float>(t_room), wall_normal, room_rgb);
      }
    }
  }
  LinkByDepthRatio(&pano, 0.75f);
  return pano;
}

TwoLayerPanorama MakeSpherePanorama(int width, int height, float radius_m) {
  TwoLayerPanorama pano(width, height);
  const uint8_t rgb[3] = {128, 128, 128};
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Vec3d dir = EquirectPixelToDirection(x + 0.5, y + 0.5, width, height);
      const double n[3] = {-dir.x, -dir.y, -dir.z};
      SetNode(&pano, kFront, x, y, radius_m, n, rgb);
    }
  }
  LinkByDepthRatio(&pano, 0.75f);
  return pano;
}

void LinkByDepthRatio(TwoLayerPanorama* pano, float min_ratio) {
  for (int l = 0; l < kNumLayers; ++l) {
    std::fill(pano->layer(l).links.begin(), pano->layer(l).links.end(), 0);
  }
  const Direction kForward[2] = {kRight, kDown};
  for (int y = 0; y < pano->height(); ++y) {
    for (int x = 0; x < pano->width(); ++x) {
      for (Direction dir : kForward) {
        int nx, ny;
        if (!pano->Neighbour(x, y, dir, &nx, &ny)) continue;
        if (nx == x && ny == y) continue;  // A 1-pixel-wide panorama.
        // Candidate pairs (layer here, layer there), most similar depth first.
        struct Pair {
          int a, b;
          float ratio;
        };
        Pair pairs[4];
        int count = 0;
        for (int a = 0; a < kNumLayers; ++a) {
          for (int b = 0; b < kNumLayers; ++b) {
            if (!pano->present(a, x, y) || !pano->present(b, nx, ny)) continue;
            const float da = pano->layer(a).depth_m[pano->index(x, y)];
            const float db = pano->layer(b).depth_m[pano->index(nx, ny)];
            pairs[count++] = {a, b, std::min(da, db) / std::max(da, db)};
          }
        }
        std::stable_sort(pairs, pairs + count,
                         [](const Pair& p, const Pair& q) { return p.ratio > q.ratio; });
        auto connect = [&](int a, int b) {
          uint8_t& la = pano->layer(a).links[pano->index(x, y)];
          uint8_t& lb = pano->layer(b).links[pano->index(nx, ny)];
          la = SetLink(la, dir, b == kFront ? Link::kFront : Link::kBack);
          lb = SetLink(lb, Opposite(dir), a == kFront ? Link::kFront : Link::kBack);
        };
        if (count == 0 || !(pairs[0].ratio > min_ratio)) continue;
        connect(pairs[0].a, pairs[0].b);
        if (pairs[0].a != pairs[0].b) continue;  // The other pair would cross this one.
        for (int k = 1; k < count; ++k) {
          if (pairs[k].a == 1 - pairs[0].a && pairs[k].b == 1 - pairs[0].b &&
              pairs[k].ratio > min_ratio) {
            connect(pairs[k].a, pairs[k].b);
          }
        }
      }
    }
  }
}

}  // namespace testing
}  // namespace casual3d
