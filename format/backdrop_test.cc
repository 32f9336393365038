#include "format/backdrop.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "format/mesh_builder.h"
#include "format/testing/test_panoramas.h"

namespace casual3d {
namespace {

using testing::MakeRoomPanorama;
using testing::MakeSpherePanorama;

double Norm(const float* p) { return std::sqrt(double(p[0]) * p[0] + double(p[1]) * p[1] + double(p[2]) * p[2]); }

// Twice the signed area of triangle t seen from the centre: the dot product of
// its normal with its first vertex (negative when counter-clockwise seen from
// the centre, as the mesh's triangles).
double Winding(const Mesh& m, size_t t) {
  const float* a = &m.positions[3 * m.indices[3 * t]];
  const float* b = &m.positions[3 * m.indices[3 * t + 1]];
  const float* c = &m.positions[3 * m.indices[3 * t + 2]];
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  return n[0] * a[0] + n[1] * a[1] + n[2] * a[2];
}

TEST(BackdropTest, EmptyPanoramaGivesAnEmptyMesh) {
  const TwoLayerPanorama p(16, 8);
  auto m = BuildBackdrop(p);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->num_vertices(), 0u);
  EXPECT_EQ(m->num_triangles(), 0u);
}

TEST(BackdropTest, RefusesBadOptionsAndTooSmallPanoramas) {
  BackdropOptions o;
  o.cell_px = -1;
  EXPECT_EQ(BuildBackdrop(TwoLayerPanorama(16, 8), o).status().code(), StatusCode::kInvalidArgument);
  o = BackdropOptions();
  o.depth_factor = 0.9;
  EXPECT_NE(o.Check().message().find("depth_factor"), std::string::npos);
  o = BackdropOptions();
  o.max_pixels = 10;
  EXPECT_EQ(BuildBackdrop(TwoLayerPanorama(16, 8), o).status().code(), StatusCode::kLimitExceeded);
  EXPECT_EQ(BuildBackdrop(TwoLayerPanorama(1, 1)).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(BackdropCellPixels(BackdropOptions(), 4096), 4);
  EXPECT_EQ(BackdropCellPixels(BackdropOptions(), 300), 1);
}

// Every quad lies behind every node of the pixels it covers, by the depth
// factor, and is wound like the mesh; its uvs point into the atlas's back
// half.
TEST(BackdropTest, LiesBehindEveryNodeItCoversAndIsWoundLikeTheMesh) {
  TwoLayerPanorama p = MakeRoomPanorama(64, 32);
  // A few back nodes farther than the front, and some pixels left empty.
  for (int x = 10; x < 14; ++x) {
    const size_t i = p.index(x, 12);
    p.layer(kBack).present[i] = 1;
    p.layer(kBack).depth_m[i] = 3.0f * p.layer(kFront).depth_m[i];
    p.layer(kBack).rgb[3 * i] = 200;
  }
  for (int y = 20; y < 32; ++y) {
    for (int x = 40; x < 64; ++x) {
      for (int l = 0; l < kNumLayers; ++l) p.layer(l).present[p.index(x, y)] = 0;
    }
  }
  BackdropOptions o;
  o.cell_px = 4;
  auto m = BuildBackdrop(p, o);
  ASSERT_TRUE(m.ok()) << m.status().message();
  ASSERT_GT(m->num_triangles(), 0u);
  auto reference = BuildMesh(MakeRoomPanorama(64, 32));
  ASSERT_TRUE(reference.ok());
  const bool mesh_negative = Winding(*reference, 0) < 0;
  for (size_t t = 0; t < m->num_triangles(); ++t) EXPECT_EQ(Winding(*m, t) < 0, mesh_negative) << t;
  // Quads: cell (i, j) with a node; j below the last vertex row (7 here).
  size_t quads = 0;
  for (int j = 0; j < 7; ++j) {
    for (int i = 0; i < 16; ++i) {
      float far = 0;
      for (int y = 4 * j; y < 4 * j + 4; ++y) {
        for (int x = 4 * i; x < 4 * i + 4; ++x) {
          for (int l = 0; l < kNumLayers; ++l) {
            if (p.present(l, x, y)) far = std::max(far, p.layer(l).depth_m[p.index(x, y)]);
          }
        }
      }
      if (far > 0) ++quads;
    }
  }
  EXPECT_EQ(m->num_triangles(), 2 * quads);
  // Each vertex at pixel (4i, 4j) is at least 1.02 times as far as every node
  // of the pixels within one cell of it (the quads it belongs to).
  for (size_t v = 0; v < m->num_vertices(); ++v) {
    const float* uv = &m->uvs[2 * v];
    EXPECT_GE(uv[1], 0.5f);
    const int x = static_cast<int>(std::lround(uv[0] * 64 - 0.5));
    const int y = static_cast<int>(std::lround((uv[1] * 2 - 1) * 32 - 0.5));
    ASSERT_EQ(x % 4, 0);
    ASSERT_EQ(y % 4, 0);
    const double r = Norm(&m->positions[3 * v]);
    for (int dy = -4; dy <= 4; ++dy) {
      for (int dx = -4; dx <= 4; ++dx) {
        const int px = ((x + dx) % 64 + 64) % 64, py = y + dy;
        if (py < 0 || py >= 32) continue;
        for (int l = 0; l < kNumLayers; ++l) {
          if (p.present(l, px, py))
            EXPECT_GE(r, 1.02 * p.layer(l).depth_m[p.index(px, py)] * (1 - 1e-6)) << v;
        }
      }
    }
    EXPECT_EQ(m->normals[3 * v], 0.0f);
  }
}

// A 128x64 front layer: a wall at depth 4 in red (200, 0, 0), with the patch
// [x0, x1) x [y0, y1) at `depth` in 200 of colour channel `channel`.
TwoLayerPanorama WallWithPatch(int x0, int x1, int y0, int y1, float depth, int channel) {
  TwoLayerPanorama p(128, 64);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 128; ++x) {
      const bool patch = x >= x0 && x < x1 && y >= y0 && y < y1;
      const size_t i = p.index(x, y);
      p.layer(kFront).present[i] = 1;
      p.layer(kFront).depth_m[i] = patch ? depth : 4.0f;
      p.layer(kFront).rgb[3 * i + (patch ? channel : 0)] = 200;
    }
  }
  return p;
}

// The backdrop of a 128x64 panorama `p` with cells of 4 pixels and a spread
// of `spread_px` (reach 1 + spread_px / 4 cells).
Mesh Backdrop(const TwoLayerPanorama& p, int spread_px) {
  BackdropOptions o;
  o.cell_px = 4;
  o.spread_px = spread_px;
  StatusOr<Mesh> m = BuildBackdrop(p, o);
  EXPECT_TRUE(m.ok()) << m.status().ToString();
  return m.ok() ? std::move(*m) : Mesh();
}

// The panorama pixel (x, y) of backdrop vertex v of a 128x64 panorama.
std::pair<int, int> PixelOf(const Mesh& m, size_t v) {
  return {static_cast<int>(std::lround(m.uvs[2 * v] * 128 - 0.5)),
          static_cast<int>(std::lround((m.uvs[2 * v + 1] * 2 - 1) * 64 - 0.5))};
}

// The index of the backdrop vertex at pixel (x, y) of a 128x64 panorama.
size_t VertexAt(const Mesh& m, int x, int y) {
  for (size_t v = 0; v < m.num_vertices(); ++v) {
    if (PixelOf(m, v) == std::pair{x, y}) return v;
  }
  ADD_FAILURE() << "no vertex at " << x << ", " << y;
  return 0;
}

// A wall (depth 4, red) with one cell of far outliers (depth 40, blue), as a
// real capture's noisy depth leaves them: the backdrop lies behind the
// outliers (depth, as every node it covers), but their colour no longer
// paints every vertex within reach; the wall's colour stays.
TEST(BackdropTest, AFewFarOutliersDoNotColourTheirWindow) {
  // Reach: 1 + 8 cells; colour from 2 cells around.
  const Mesh m = Backdrop(WallWithPatch(60, 64, 28, 32, 40.0f, 2), 32);
  int within_reach = 0;
  for (size_t v = 0; v < m.num_vertices(); ++v) {
    const auto [x, y] = PixelOf(m, v);
    if (std::abs(x - 60) > 12 || std::abs(y - 28) > 12) continue;
    ++within_reach;
    EXPECT_NEAR(Norm(&m.positions[3 * v]), 40.0 * 1.02, 1e-3) << x << ", " << y;
    // The outlier's cell weighs at most 1.5^4 times a wall cell: less than
    // a fifth of the 25 cells' weight where it is in a vertex's window.
    EXPECT_GE(m.colors[3 * v], 150) << x << ", " << y;
    EXPECT_LE(m.colors[3 * v + 2], 50) << x << ", " << y;
  }
  EXPECT_EQ(within_reach, 49);
}

// A near square (depth 1, green) in front of a far wall (depth 4, red): the
// backdrop takes the wall's depth behind the square's rim, as far as the
// spread reaches, and the square's own further inside. Its colour is the
// wall's at the rim, and inside the square the square's: the surface it shows
// through there, where a sheet of the square is left out.
TEST(BackdropTest, TheBackgroundSpreadsBehindTheForeground) {
  // Reach: 1 + 2 cells; colour from 1 cell around.
  const Mesh m = Backdrop(WallWithPatch(32, 96, 8, 56, 1.0f, 1), 8);
  // On the square's edge: the wall's depth, and its colour with at most a
  // twentieth of the square's (a wall cell weighs (4 / 1)^4 times more).
  size_t v = VertexAt(m, 32, 32);
  EXPECT_NEAR(Norm(&m.positions[3 * v]), 4.0 * 1.02, 1e-4);
  EXPECT_GE(m.colors[3 * v], 190);
  EXPECT_LE(m.colors[3 * v + 1], 10);
  // Inside the square by 8 pixels (2 cells, within reach): the wall's depth,
  // the square's colour.
  v = VertexAt(m, 40, 32);
  EXPECT_NEAR(Norm(&m.positions[3 * v]), 4.0 * 1.02, 1e-4);
  EXPECT_EQ(m.colors[3 * v], 0);
  EXPECT_EQ(m.colors[3 * v + 1], 200);
  // 16 pixels inside (4 cells, beyond reach): the square itself.
  v = VertexAt(m, 48, 32);
  EXPECT_NEAR(Norm(&m.positions[3 * v]), 1.0 * 1.02, 1e-5);
  EXPECT_EQ(m.colors[3 * v], 0);
  EXPECT_EQ(m.colors[3 * v + 1], 200);
}

// The same square and wall with the sky elsewhere: a block of nodes 1000
// times farther (the depth sky pixels get) and one node at +infinity (an
// invalid depth, which takes no part in the colour). The weights stay
// relative: the wall's colour still wins at the square's rim.
TEST(BackdropTest, FarSkyElsewhereLeavesTheRimTheWallsColour) {
  TwoLayerPanorama p = WallWithPatch(32, 96, 8, 56, 1.0f, 1);
  for (int y = 56; y < 64; ++y) {
    for (int x = 104; x < 112; ++x) p.layer(kFront).depth_m[p.index(x, y)] = 4000.0f;
  }
  p.layer(kFront).depth_m[p.index(4, 4)] = std::numeric_limits<float>::infinity();
  const Mesh m = Backdrop(p, 8);
  const size_t v = VertexAt(m, 32, 32);
  EXPECT_GE(m.colors[3 * v], 190);
  EXPECT_LE(m.colors[3 * v + 1], 10);
}

TEST(BackdropTest, AFullSphereIsClosedAcrossTheSeam) {
  const TwoLayerPanorama p = MakeSpherePanorama(64, 32, 5.0f);
  BackdropOptions o;
  o.cell_px = 8;
  auto m = BuildBackdrop(p, o);
  ASSERT_TRUE(m.ok());
  // 8 columns of cells, vertex rows at y = 0, 8, 16, 24: 3 rows of quads.
  EXPECT_EQ(m->num_triangles(), 2u * 8 * 3);
  // 9 vertex columns (the 9th the seam copy) x 4 rows.
  EXPECT_EQ(m->num_vertices(), 9u * 4);
  float max_u = 0;
  for (size_t v = 0; v < m->num_vertices(); ++v) {
    max_u = std::max(max_u, m->uvs[2 * v]);
    EXPECT_NEAR(Norm(&m->positions[3 * v]), 5.0 * 1.02, 1e-4);
  }
  EXPECT_FLOAT_EQ(max_u, 64.5f / 64);
}

TEST(BackdropTest, AppendMeshOffsetsIndices) {
  const TwoLayerPanorama p = MakeSpherePanorama(32, 16, 2.0f);
  auto mesh = BuildMesh(p);
  auto backdrop = BuildBackdrop(p);
  ASSERT_TRUE(mesh.ok() && backdrop.ok());
  Mesh both = *mesh;
  AppendMesh(*backdrop, &both);
  EXPECT_EQ(both.num_vertices(), mesh->num_vertices() + backdrop->num_vertices());
  EXPECT_EQ(both.num_triangles(), mesh->num_triangles() + backdrop->num_triangles());
  EXPECT_EQ(both.indices.back(), backdrop->indices.back() + mesh->num_vertices());
  EXPECT_EQ(both.colors.size(), 3 * both.num_vertices());
}

}  // namespace
}  // namespace casual3d
