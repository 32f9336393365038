#include "reconstruct/normals/normals.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "reconstruct/fuse/fuse.h"

namespace casual3d::normals {
namespace {

constexpr int W = 512, H = 256;

// A room: walls at |z| = 4 and |x| = 4, a floor 1.5 m down, sky (1 km, uniform blue) above 30
// degrees latitude, and a square plate 1.5 m ahead turned 30 degrees about the
// vertical axis. `stripes` adds a luminance texture to the front wall.
struct Room {
  Image8 rgb{W, H, 3, 0};
  ImageF depth{W, H, 1, 0.0f};
  static constexpr double kTurn = 30.0 * kPi / 180.0;

  static double PlateHit(const Vec3d& d) {
    // Plane through (0, 0, -1.5) with normal (sin t, 0, cos t).
    const double nx = std::sin(kTurn), nz = std::cos(kTurn);
    const double denom = d.x * nx + d.z * nz;
    if (std::abs(denom) < 1e-9) return -1;
    const double t = (-1.5 * nz) / denom;
    if (t <= 0) return -1;
    const double px = t * d.x, py = t * d.y, pz = t * d.z + 1.5;
    const double along = px * nz - pz * nx;  // In-plane horizontal coordinate.
    return (std::abs(along) < 0.4 && std::abs(py) < 0.4) ? t : -1;
  }

  explicit Room(bool stripes) {
    for (int y = 0; y < H; ++y) {
      for (int x = 0; x < W; ++x) {
        const Vec3d d = EquirectPixelToDirection(x + 0.5, y + 0.5, W, H);
        const double lat = std::asin(d.y) * 180.0 / kPi;
        double t = PlateHit(d);
        uint8_t c[3] = {180, 160, 140};
        if (t < 0) {
          if (lat > 30) {
            t = 1000.0;
            c[0] = 120; c[1] = 170; c[2] = 230;
          } else {
            const double tz = 4.0 / std::max(std::abs(d.z), 1e-9);
            const double tx = 4.0 / std::max(std::abs(d.x), 1e-9);
            const double ty = d.y < 0 ? 1.5 / -d.y : 1e9;  // Floor 1.5 m below.
            t = std::min({tx, tz, ty});
            if (stripes && d.z < 0 && tz < tx) {
              const double wx = t * d.x;
              c[0] = c[1] = c[2] = static_cast<uint8_t>(128 + 60 * std::sin(wx * 25.0));
            }
          }
        }
        depth.at(x, y) = static_cast<float>(t);
        for (int k = 0; k < 3; ++k) rgb.at(x, y, k) = c[k];
      }
    }
  }

  TwoLayerPanorama Fused() const {
    ImageF no_back(W, H, 1, 0.0f);
    Image8 back_rgb(W, H, 3, 0);
    fuse::FuseOptions options;
    options.expansion_fraction = 0;
    return fuse::Fuse({&rgb, &depth, &back_rgb, &no_back, {}}, options);
  }
};

double Length(const float* n) { return std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]); }

double AngleDeg(const float* n, double x, double y, double z) {
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const double c = (n[0] * x + n[1] * y + n[2] * z) / len;
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi;
}

TEST(NormalsTest, BaseNormalsFollowSurfacesAndStopAtDepthEdges) {
  Room room(false);
  TwoLayerPanorama pano = room.Fused();
  NormalOptions options;
  options.detail_strength = 0;
  const NormalStats stats = ComputeNormals(&pano, options);
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  EXPECT_EQ(stats.nodes, W * H);
  const LayerData& F = pano.layer(kFront);
  int plate = 0, wall = 0;
  double worst_plate = 0, worst_wall = 0;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const Vec3d d = EquirectPixelToDirection(x + 0.5, y + 0.5, W, H);
      const float* n = &F.normal[3 * pano.index(x, y)];
      if (Room::PlateHit(d) > 0) {
        // Faces the centre: (-sin t, 0, ... ) flipped towards the origin.
        worst_plate = std::max(worst_plate, AngleDeg(n, std::sin(Room::kTurn), 0, std::cos(Room::kTurn)));
        ++plate;
      } else if (d.z < -0.9 && std::abs(std::asin(d.y)) < 10 * kPi / 180) {
        // The front wall (facing +z), including pixels right next to the plate,
        // away from its crease with the floor (creases are smoothed, by design).
        worst_wall = std::max(worst_wall, AngleDeg(n, 0, 0, 1));
        ++wall;
      }
    }
  }
  ASSERT_GT(plate, 500);
  ASSERT_GT(wall, 900);
  EXPECT_LT(worst_plate, 3.0);
  EXPECT_LT(worst_wall, 3.0);
}

TEST(NormalsTest, SkyIsUnlitAndDetailTiltsNormals) {
  Room room(true);
  TwoLayerPanorama pano = room.Fused();
  const NormalStats stats = ComputeNormals(&pano, NormalOptions());
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  const LayerData& F = pano.layer(kFront);
  long sky_pixels = 0, sky_zero = 0, lit_zero = 0;
  double tilt_sum = 0;
  int tilt_count = 0;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const float* n = &F.normal[3 * pano.index(x, y)];
      const bool zero = n[0] == 0 && n[1] == 0 && n[2] == 0;
      if (F.depth_m[pano.index(x, y)] > 500) {
        ++sky_pixels;
        sky_zero += zero;
      } else {
        lit_zero += zero;
      }
      const Vec3d d = EquirectPixelToDirection(x + 0.5, y + 0.5, W, H);
      if (d.z < -0.95 && Room::PlateHit(d) < 0) {
        tilt_sum += AngleDeg(n, 0, 0, 1);
        ++tilt_count;
      }
    }
  }
  EXPECT_EQ(sky_zero, sky_pixels);
  EXPECT_EQ(stats.sky_nodes, sky_pixels);
  EXPECT_EQ(lit_zero, 0);
  // The stripes emboss the wall: a clear mean tilt, but not a wild one.
  ASSERT_GT(tilt_count, 100);
  EXPECT_GT(tilt_sum / tilt_count, 2.0);
  EXPECT_LT(tilt_sum / tilt_count, 30.0);
}

// Back nodes are linked to back nodes: the wall behind a plate, held in the
// back layer, gets the wall's normal, not the plate's.
TEST(NormalsTest, TheBackLayerHasItsOwnSurfaces) {
  Room room(false);
  // The back layer: the room behind the plate.
  ImageF back_depth(W, H, 1, 0.0f);
  Image8 back_rgb(W, H, 3, 0);
  int back_wall = 0;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const Vec3d d = EquirectPixelToDirection(x + 0.5, y + 0.5, W, H);
      if (Room::PlateHit(d) < 0) continue;
      const double tz = 4.0 / std::abs(d.z), tx = 4.0 / std::max(std::abs(d.x), 1e-9);
      const double ty = d.y < 0 ? 1.5 / -d.y : 1e9;
      back_depth.at(x, y) = static_cast<float>(std::min({tx, tz, ty}));
      for (int k = 0; k < 3; ++k) back_rgb.at(x, y, k) = room.rgb.at(0, H / 2, k);
      back_wall += tz < std::min(tx, ty);
    }
  }
  ASSERT_GT(back_wall, 500);
  fuse::FuseOptions fuse_options;
  fuse_options.expansion_fraction = 0;
  TwoLayerPanorama pano =
      fuse::Fuse({&room.rgb, &room.depth, &back_rgb, &back_depth, {}}, fuse_options);
  NormalOptions options;
  options.detail_strength = 0;
  ComputeNormals(&pano, options);
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  // The wall behind the plate, in the back layer, faces +z like the front
  // wall around it.
  const LayerData& B = pano.layer(kBack);
  int back = 0;
  double worst_back = 0;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const size_t i = pano.index(x, y);
      if (!B.present[i]) continue;
      const Vec3d d = EquirectPixelToDirection(x + 0.5, y + 0.5, W, H);
      const double tz = 4.0 / std::abs(d.z), tx = 4.0 / std::max(std::abs(d.x), 1e-9);
      // Away from the creases with the floor and the side walls (smoothed,
      // by design).
      if (!(tz < 0.95 * tx) || std::abs(std::asin(d.y)) > 10 * kPi / 180) continue;
      ASSERT_NEAR(Length(&B.normal[3 * i]), 1.0, 1e-4) << "back node " << x << "," << y;
      worst_back = std::max(worst_back, AngleDeg(&B.normal[3 * i], 0, 0, 1));
      ++back;
    }
  }
  ASSERT_GT(back, 300);
  EXPECT_LT(worst_back, 0.5);
}

// Turning the scene half a turn moves the striped front wall onto the +-180
// degree seam: its normals, detail included, turn with it, so neighbours
// across the seam are the ones beside it.
TEST(NormalsTest, NormalsTurnWithTheSceneAcrossTheSeam) {
  Room room(true);
  Room turned(true);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int from = (x + W / 2) % W;
      turned.depth.at(x, y) = room.depth.at(from, y);
      for (int k = 0; k < 3; ++k) turned.rgb.at(x, y, k) = room.rgb.at(from, y, k);
    }
  TwoLayerPanorama pano = room.Fused(), pano_turned = turned.Fused();
  ComputeNormals(&pano, NormalOptions());
  ComputeNormals(&pano_turned, NormalOptions());
  const LayerData& F = pano.layer(kFront);
  const LayerData& T = pano_turned.layer(kFront);
  double worst = 0;
  int seam = 0;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const int tx = (x + W / 2) % W;  // Where pixel x of `room` is in `turned`.
      const float* n = &F.normal[3 * pano.index(x, y)];
      const float* t = &T.normal[3 * pano_turned.index(tx, y)];
      // Half a turn about the vertical: (x, y, z) -> (-x, y, -z).
      for (const double e : {-n[0] - t[0], n[1] - t[1], -n[2] - t[2]}) worst = std::max(worst, std::abs(e));
      seam += (tx == 0 || tx == W - 1) && std::abs(std::asin(EquirectPixelToDirection(x + 0.5, y + 0.5, W, H).y)) < 0.3;
    }
  }
  ASSERT_GT(seam, 80);
  EXPECT_LT(worst, 1e-3);
}

TEST(NormalsTest, RejectsBadOptions) {
  NormalOptions options;
  EXPECT_TRUE(options.Check().ok());
  options.smoothness = 0;
  EXPECT_FALSE(options.Check().ok());
}

}  // namespace
}  // namespace casual3d::normals
