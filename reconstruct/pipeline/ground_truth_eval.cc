#include "reconstruct/pipeline/ground_truth_eval.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "reconstruct/io/exr_io.h"

namespace casual3d::pipeline {
namespace {

constexpr int kEdgeRadius = 5;         // Pixels.
constexpr float kEdgeRatio = 0.9f;     // Depth ratio of a depth edge.
constexpr float kAccuracy = 0.03f;     // Front accuracy tolerance.
constexpr float kMatch = 0.05f;        // "Shows the true surface" tolerance.

bool Finite(float d) { return std::isfinite(d) && d > 0; }

}  // namespace

GroundTruthComparison CompareWithGroundTruth(const TwoLayerPanorama& pano, const ImageF& front_depth,
                                             const ImageF& back_depth, const ImageF& front_normal,
                                             Image8* map) {
  const int W = pano.width(), H = pano.height();
  if (front_depth.width() != W || front_depth.height() != H || back_depth.width() != W ||
      back_depth.height() != H || front_normal.width() != W || front_normal.height() != H ||
      front_normal.channels() != 3) {
    throw std::runtime_error("ground truth is " + std::to_string(front_depth.width()) + "x" +
                             std::to_string(front_depth.height()) + ", the panorama " +
                             std::to_string(W) + "x" + std::to_string(H) +
                             ": compare at the same size");
  }
  GroundTruthComparison c;
  if (map) *map = Image8(W, H, 3, 0);
  auto paint = [&](int x, int y, uint8_t r, uint8_t g, uint8_t b) {
    if (!map) return;
    map->at(x, y, 0) = r;
    map->at(x, y, 1) = g;
    map->at(x, y, 2) = b;
  };
  // Depth predicted at pixel (qx, qy) by the plane through pixel (px, py)'s
  // ground-truth point with its normal; 0 if undefined.
  auto plane_predict = [&](int px, int py, int qx, int qy) {
    const float dp = front_depth.at(px, py);
    const Vec3d rp = EquirectPixelToDirection(px + 0.5, py + 0.5, W, H);
    const Vec3d rq = EquirectPixelToDirection(qx + 0.5, qy + 0.5, W, H);
    const double nx = front_normal.at(px, py, 0), ny = front_normal.at(px, py, 1),
                 nz = front_normal.at(px, py, 2);
    const double num = dp * (nx * rp.x + ny * rp.y + nz * rp.z);
    const double den = nx * rq.x + ny * rq.y + nz * rq.z;
    if (!std::isfinite(num) || std::abs(den) < 1e-6) return 0.0;
    const double d = num / den;
    return d > 0 ? d : 0.0;
  };
  auto off_plane = [&](int px, int py, int qx, int qy) {
    const double pred = plane_predict(px, py, qx, qy);
    const double dq = front_depth.at(qx, qy);
    return !(pred > 0) || std::abs(dq - pred) > (1.0 - kEdgeRatio) * dq;
  };
  const LayerData& F = pano.layer(kFront);
  const LayerData& B = pano.layer(kBack);
  // Sky (+inf) counts as the farthest surface for edges: use a large depth.
  auto truth = [&](int x, int y) {
    const float d = front_depth.at(x, y);
    return std::isinf(d) ? 1e9f : d;
  };
  // Near side of a depth edge: some pixel within the radius is >= 10% farther.
  std::vector<uint8_t> near_edge(static_cast<size_t>(W) * H, 0);
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const float d = truth(x, y);
      if (!(d > 0) || std::isnan(d)) continue;
      bool edge = false;
      for (int dy = -kEdgeRadius; dy <= kEdgeRadius && !edge; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= H) continue;
        for (int dx = -kEdgeRadius; dx <= kEdgeRadius; ++dx) {
          const int xx = WrapColumn(x + dx, W);
          const float e = truth(xx, yy);
          // A farther pixel that the plane of this pixel's surface does not
          // explain: a depth edge, not a grazing floor.
          if (e > 0 && d < kEdgeRatio * e && off_plane(x, y, xx, yy)) {
            edge = true;
            break;
          }
        }
      }
      near_edge[pano.index(x, y)] = edge;
    }
  }
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const size_t i = pano.index(x, y);
      const float gt = front_depth.at(x, y);
      if (Finite(gt)) {
        ++c.front_truth_pixels;
        if (F.present[i]) {
          ++c.front_covered;
          const bool ok = std::abs(F.depth_m[i] - gt) <= kAccuracy * gt;
          c.front_within_3pct += ok;
          if (ok) paint(x, y, 128, 128, 128); else paint(x, y, 220, 30, 30);
        }
      }
      const float back = back_depth.at(x, y);
      if (near_edge[i] && F.present[i] && !std::isnan(back) && back > 0) {
        ++c.back_edge_pixels;
        c.back_edge_present += B.present[i] != 0;
        if (B.present[i]) paint(x, y, 40, 200, 40); else paint(x, y, 230, 0, 230);
      }
      // Edge pairs to the right and below.
      for (int d = 0; d < 2; ++d) {
        const Direction dir = d == 0 ? kRight : kDown;
        int nx, ny;
        if (!pano.Neighbour(x, y, dir, &nx, &ny)) continue;
        const size_t j = pano.index(nx, ny);
        const float a = truth(x, y), b = truth(nx, ny);
        if (!(a > 0 && b > 0) || std::min(a, b) >= kEdgeRatio * std::max(a, b)) continue;
        if (!off_plane(x, y, nx, ny) || !off_plane(nx, ny, x, y)) continue;  // One smooth surface.
        if (!F.present[i] || !F.present[j]) continue;
        if (std::abs(F.depth_m[i] - a) > kMatch * a || std::abs(F.depth_m[j] - b) > kMatch * b) continue;
        ++c.edge_pairs;
        c.edge_pairs_linked += GetLink(F.links[i], dir) == Link::kFront;
      }
    }
  }
  return c;
}

GroundTruthComparison CompareWithGroundTruthFile(const TwoLayerPanorama& pano,
                                                 const std::string& panorama_exr, Image8* map) {
  const ImageF all = io::ReadExrChannels(
      panorama_exr, {"front.Z", "back.Z", "front.NX", "front.NY", "front.NZ"});
  const int w = all.width(), h = all.height();
  ImageF front(w, h, 1), back(w, h, 1), normal(w, h, 3);
  for (size_t i = 0; i < front.size(); ++i) {
    front.vector()[i] = all.vector()[5 * i];
    back.vector()[i] = all.vector()[5 * i + 1];
    for (int c = 0; c < 3; ++c) normal.vector()[3 * i + c] = all.vector()[5 * i + 2 + c];
  }
  return CompareWithGroundTruth(pano, front, back, normal, map);
}

}  // namespace casual3d::pipeline
