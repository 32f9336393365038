#include "format/mesh_builder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>

#include "format/color_atlas.h"
#include "format/equirect.h"
#include "format/testing/mesh_checksum.h"
#include "format/testing/test_panoramas.h"

namespace casual3d {
namespace {

struct NodeId {
  int x, y, layer;
  bool seam;
  int half;  // The atlas half its uv points into.
};

// Recovers the node of a vertex: its pixel and atlas half from the uv
// (spec/mesh.md Sec. 3), its layer from the distance of its position to the
// centre where both layers have a node at that pixel.
NodeId NodeOfVertex(const TwoLayerPanorama& p, const Mesh& m, uint32_t v) {
  const int w = p.width(), h = p.height();
  const double u = m.uvs[2 * v] * static_cast<double>(w) - 0.5;
  const double t = m.uvs[2 * v + 1] * 2.0 * h - 0.5;
  const int ux = static_cast<int>(std::lround(u));
  const int row = static_cast<int>(std::lround(t));
  const int x = ux % w, y = row % h;
  const size_t i = p.index(x, y);
  const float* q = &m.positions[3 * v];
  const double r = std::sqrt(double{q[0]} * q[0] + double{q[1]} * q[1] + double{q[2]} * q[2]);
  int layer = p.layer(kFront).present[i] ? kFront : kBack;
  if (p.layer(kFront).present[i] && p.layer(kBack).present[i] &&
      std::abs(r - p.layer(kBack).depth_m[i]) < std::abs(r - p.layer(kFront).depth_m[i])) {
    layer = kBack;
  }
  return {x, y, layer, ux >= w, row / h};
}

// Sets a node with depth d and a normal facing the centre.
void SetNode(TwoLayerPanorama* p, int l, int x, int y, float d) {
  const size_t i = p->index(x, y);
  LayerData& L = p->layer(l);
  L.present[i] = 1;
  L.depth_m[i] = d;
  const Vec3d dir = EquirectPixelToDirection(x + 0.5, y + 0.5, p->width(), p->height());
  L.normal[3 * i] = static_cast<float>(-dir.x);
  L.normal[3 * i + 1] = static_cast<float>(-dir.y);
  L.normal[3 * i + 2] = static_cast<float>(-dir.z);
  L.label[i] = static_cast<uint8_t>(l);
  L.rgb[3 * i] = static_cast<uint8_t>(10 * x);
  L.rgb[3 * i + 1] = static_cast<uint8_t>(10 * y);
  L.rgb[3 * i + 2] = static_cast<uint8_t>(100 * l);
}

// A w x h panorama whose front depth is depth(x, y), linked by depth ratio.
template <typename F>
TwoLayerPanorama FrontOnly(int w, int h, F depth) {
  TwoLayerPanorama p(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) SetNode(&p, kFront, x, y, depth(x, y));
  }
  testing::LinkByDepthRatio(&p, 0.75f);
  return p;
}

// The number of vertices whose colour differs from the atlas texel at their
// uv (format/color_atlas.h), i.e. where atlas texturing shows another colour
// than the node's at the vertex itself.
int CountVerticesWithOtherAtlasColor(const TwoLayerPanorama& p, const Mesh& m) {
  const Image8 atlas = BuildColorAtlas(p);
  int wrong = 0;
  for (size_t v = 0; v < m.num_vertices(); ++v) {
    const int x = static_cast<int>(std::lround(m.uvs[2 * v] * p.width() - 0.5)) % p.width();
    const int y = static_cast<int>(std::lround(m.uvs[2 * v + 1] * 2.0 * p.height() - 0.5));
    bool same = true;
    for (int c = 0; c < 3; ++c) same = same && atlas.at(x, y, c) == m.colors[3 * v + c];
    wrong += same ? 0 : 1;
  }
  return wrong;
}

bool Linked(const TwoLayerPanorama& p, const NodeId& a, const NodeId& b) {
  for (int d = 0; d < kNumDirections; ++d) {
    int nx, ny;
    if (!p.Neighbour(a.x, a.y, static_cast<Direction>(d), &nx, &ny)) continue;
    if (nx != b.x || ny != b.y) continue;
    const Link l = GetLink(p.layer(a.layer).links[p.index(a.x, a.y)], static_cast<Direction>(d));
    if (l != Link::kNone && (l == Link::kFront ? kFront : kBack) == b.layer) return true;
  }
  return false;
}

// Every triangle: two of its edges are links, the third is the diagonal of a
// pixel quad; it faces the centre (counter-clockwise seen from the origin).
void CheckTriangles(const TwoLayerPanorama& p, const Mesh& m) {
  const int w = p.width();
  for (size_t t = 0; t < m.num_triangles(); ++t) {
    NodeId n[3];
    for (int k = 0; k < 3; ++k) n[k] = NodeOfVertex(p, m, m.indices[3 * t + k]);
    int links = 0;
    for (int k = 0; k < 3; ++k) links += Linked(p, n[k], n[(k + 1) % 3]);
    ASSERT_EQ(links, 2) << "triangle " << t;
    // One atlas half per triangle (spec/mesh.md Sec. 4.4): its layer's if it
    // has one layer.
    EXPECT_EQ(n[0].half, n[1].half) << "triangle " << t;
    EXPECT_EQ(n[0].half, n[2].half) << "triangle " << t;
    if (n[0].layer == n[1].layer && n[0].layer == n[2].layer) {
      EXPECT_EQ(n[0].half, n[0].layer) << "triangle " << t;
    }
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = m.indices[3 * t + k];
      const size_t i = p.index(n[k].x, n[k].y);
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(m.colors[3 * v + c], p.layer(n[k].layer).rgb[3 * i + c]) << "vertex " << v;
      }
    }
    for (int k = 0; k < 3; ++k) {
      const NodeId& a = n[k];
      const NodeId& b = n[(k + 1) % 3];
      if (Linked(p, a, b)) continue;
      const int dx = std::abs(a.x - b.x);
      EXPECT_TRUE(dx == 1 || dx == w - 1) << "triangle " << t;
      EXPECT_EQ(std::abs(a.y - b.y), 1) << "triangle " << t;
    }
    const float* p0 = &m.positions[3 * m.indices[3 * t]];
    const float* p1 = &m.positions[3 * m.indices[3 * t + 1]];
    const float* p2 = &m.positions[3 * m.indices[3 * t + 2]];
    const double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    const double nrm[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                           e1[0] * e2[1] - e1[1] * e2[0]};
    const double c[3] = {p0[0] + p1[0] + p2[0], p0[1] + p1[1] + p2[1], p0[2] + p1[2] + p2[2]};
    EXPECT_LT(nrm[0] * c[0] + nrm[1] * c[1] + nrm[2] * c[2], 0.0) << "triangle " << t;
  }
}

TEST(MeshBuilderTest, FullyLinkedGridGivesTwoTrianglesPerQuadAndSeamCopies) {
  const TwoLayerPanorama p = FrontOnly(8, 4, [](int, int) { return 2.0f; });
  auto mesh = BuildMesh(p);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->num_triangles(), 8u * 3 * 2);
  EXPECT_EQ(mesh->num_vertices(), 32u + 4);  // One per node, one seam copy per row.
  CheckTriangles(p, *mesh);
  // Vertex order: (row, column, layer), then seam copies by row.
  for (uint32_t v = 0; v < 32; ++v) {
    const NodeId n = NodeOfVertex(p, *mesh, v);
    EXPECT_EQ(n.y * 8 + n.x, static_cast<int>(v));
    EXPECT_FALSE(n.seam);
  }
  for (uint32_t v = 32; v < 36; ++v) {
    const NodeId n = NodeOfVertex(p, *mesh, v);
    EXPECT_TRUE(n.seam);
    EXPECT_EQ(n.x, 0);
    EXPECT_EQ(n.y, static_cast<int>(v - 32));
    EXPECT_FLOAT_EQ(mesh->uvs[2 * v], 8.5f / 8);
    for (int c = 0; c < 3; ++c) {  // Same position as the regular copy.
      EXPECT_EQ(mesh->positions[3 * v + c], mesh->positions[3 * (8 * n.y) + c]);
    }
  }
  // Quad (0, 0): corner B then corner C triangles, A-D diagonal.
  EXPECT_EQ(mesh->indices[0], 1u);
  EXPECT_EQ(mesh->indices[1], 0u);
  EXPECT_EQ(mesh->indices[2], 9u);
  EXPECT_EQ(mesh->indices[3], 8u);
  EXPECT_EQ(mesh->indices[4], 9u);
  EXPECT_EQ(mesh->indices[5], 0u);
  // The last quad of row 0 wraps: its B and D are seam copies.
  EXPECT_EQ(mesh->indices[6 * 7 + 0], 32u);
  EXPECT_EQ(mesh->indices[6 * 7 + 1], 7u);
  EXPECT_EQ(mesh->indices[6 * 7 + 2], 33u);
}

TEST(MeshBuilderTest, VertexAttributesFollowTheSpec) {
  TwoLayerPanorama p = FrontOnly(16, 8, [](int x, int y) { return 1.0f + 0.01f * (x + y); });
  auto mesh = BuildMesh(p);
  ASSERT_TRUE(mesh.ok());
  for (uint32_t v = 0; v < 16 * 8; ++v) {
    const int x = v % 16, y = v / 16;
    const size_t i = p.index(x, y);
    const double d = p.layer(kFront).depth_m[i];
    const Vec3d dir = EquirectPixelToDirection(x + 0.5, y + 0.5, 16, 8);
    EXPECT_NEAR(mesh->positions[3 * v + 0], dir.x * d, 1e-6);
    EXPECT_NEAR(mesh->positions[3 * v + 1], dir.y * d, 1e-6);
    EXPECT_NEAR(mesh->positions[3 * v + 2], dir.z * d, 1e-6);
    EXPECT_EQ(mesh->uvs[2 * v], static_cast<float>((x + 0.5) / 16));
    EXPECT_EQ(mesh->uvs[2 * v + 1], static_cast<float>((y + 0.5) / 16));
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(mesh->normals[3 * v + c], p.layer(kFront).normal[3 * i + c]);
      EXPECT_EQ(mesh->colors[3 * v + c], p.layer(kFront).rgb[3 * i + c]);
    }
  }
  // Pole rows are half a pixel from the poles (latitude +-7/16 pi) and are not
  // joined to each other.
  EXPECT_NEAR(mesh->positions[1], std::cos(kPi / 16), 1e-6);
  EXPECT_NEAR(mesh->positions[3 * (7 * 16) + 1],
              -std::cos(kPi / 16) * p.layer(kFront).depth_m[p.index(0, 7)], 1e-6);
  CheckTriangles(p, *mesh);
}

TEST(MeshBuilderTest, DepthEdgesStayOpen) {
  // Columns 0-3 at 1 m, 4-7 at 4 m: no links across x = 3|4 nor across the seam.
  const TwoLayerPanorama p = FrontOnly(8, 4, [](int x, int) { return x < 4 ? 1.0f : 4.0f; });
  auto mesh = BuildMesh(p);
  ASSERT_TRUE(mesh.ok());
  EXPECT_EQ(mesh->num_triangles(), 6u * 3 * 2);
  EXPECT_EQ(mesh->num_vertices(), 32u);  // No seam copy: nothing crosses the seam.
  CheckTriangles(p, *mesh);
}

TEST(MeshBuilderTest, ThreeLinkedCornersGiveOneTriangle) {
  // One quad row; node (5, 1) is far away and linked to nothing.
  TwoLayerPanorama p = FrontOnly(8, 2, [](int x, int y) { return x == 5 && y == 1 ? 9.0f : 2.0f; });
  auto mesh = BuildMesh(p);
  ASSERT_TRUE(mesh.ok());
  EXPECT_EQ(mesh->num_triangles(), 6u * 2 + 2);
  EXPECT_EQ(mesh->num_vertices(), 16u - 1 + 2);
  CheckTriangles(p, *mesh);
  // Quad 4: corner A's triangle (A, C, B) = (4,0), (4,1), (5,0).
  // Quad 5: corner B's triangle (B, A, D) = (6,0), (5,0), (6,1).
  std::set<std::tuple<int, int, int, int, int, int>> tris;
  for (size_t t = 0; t < mesh->num_triangles(); ++t) {
    NodeId n[3];
    for (int k = 0; k < 3; ++k) n[k] = NodeOfVertex(p, *mesh, mesh->indices[3 * t + k]);
    tris.insert({n[0].x, n[0].y, n[1].x, n[1].y, n[2].x, n[2].y});
  }
  EXPECT_TRUE(tris.count({4, 0, 4, 1, 5, 0}));
  EXPECT_TRUE(tris.count({6, 0, 5, 0, 6, 1}));
}

// Background at 4 m everywhere; columns 3-4 hold an object at 1 m in front and
// the background in the back layer.
TwoLayerPanorama ObjectInFront() {
  TwoLayerPanorama p(8, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 8; ++x) {
      const bool object = x == 3 || x == 4;
      SetNode(&p, kFront, x, y, object ? 1.0f : 4.0f);
      if (object) SetNode(&p, kBack, x, y, 4.0f);
    }
  }
  testing::LinkByDepthRatio(&p, 0.75f);
  return p;
}

TEST(MeshBuilderTest, BackLayerFillsDisocclusion) {
  const TwoLayerPanorama p = ObjectInFront();
  ASSERT_TRUE(p.Validate().ok()) << p.Validate().ToString();
  auto mesh = BuildMesh(p);
  ASSERT_TRUE(mesh.ok());
  // The background sheet closes over all 8 x 3 quads; the object adds 1 x 3.
  EXPECT_EQ(mesh->num_triangles(), 8u * 3 * 2 + 3 * 2);
  // 32 front and 8 back nodes; the front nodes of columns 2 and 5 that
  // triangles join to back nodes also have a copy in the back half of the
  // atlas (which shows their colour there: no back node at their pixels);
  // 4 seam copies.
  EXPECT_EQ(mesh->num_vertices(), 32u + 8 + 8 + 4);
  CheckTriangles(p, *mesh);
  EXPECT_EQ(CountVerticesWithOtherAtlasColor(p, *mesh), 0);
  // Vertex order: (row, column, layer, own half first). Row 0: (0..2, 0)
  // front, the back-half copy of (2, 0), (3, 0) front and back, (4, 0) front
  // and back, (5, 0) front and its copy, (6, 0), (7, 0).
  const int want[][4] = {{0, 0, kFront, kFront}, {1, 0, kFront, kFront}, {2, 0, kFront, kFront},
                         {2, 0, kFront, kBack},  {3, 0, kFront, kFront}, {3, 0, kBack, kBack},
                         {4, 0, kFront, kFront}, {4, 0, kBack, kBack},   {5, 0, kFront, kFront},
                         {5, 0, kFront, kBack},  {6, 0, kFront, kFront}, {7, 0, kFront, kFront}};
  for (uint32_t v = 0; v < 12; ++v) {
    const NodeId n = NodeOfVertex(p, *mesh, v);
    EXPECT_EQ(n.x, want[v][0]) << "vertex " << v;
    EXPECT_EQ(n.y, want[v][1]) << "vertex " << v;
    EXPECT_EQ(n.layer, want[v][2]) << "vertex " << v;
    EXPECT_EQ(n.half, want[v][3]) << "vertex " << v;
  }

  MeshBuildOptions front_only;
  front_only.include_back_layer = false;
  auto front = BuildMesh(p, front_only);
  ASSERT_TRUE(front.ok());
  // Quads 2 and 4 straddle the depth edges and stay open.
  EXPECT_EQ(front->num_triangles(), 5u * 3 * 2 + 3 * 2);
  EXPECT_EQ(front->num_vertices(), 32u + 4);
}

// One quad (spec/mesh.md Sec. 4.4): the corner-B triangle (B front, A back,
// D front) of quad (0, 0), with back nodes also at B and, if `back_at_d`, at D,
// so that either atlas half shows some vertex another node's colour.
TwoLayerPanorama CrossLayerQuad(bool back_at_d) {
  TwoLayerPanorama p(4, 2);
  for (int x = 0; x < 2; ++x) {
    for (int y = 0; y < 2; ++y) SetNode(&p, kFront, x, y, 2.0f);
  }
  SetNode(&p, kBack, 0, 0, 3.0f);
  SetNode(&p, kBack, 1, 0, 3.0f);
  if (back_at_d) SetNode(&p, kBack, 1, 1, 3.0f);
  auto link = [&](int l, int x, int y, Direction d, Link to) {
    uint8_t& links = p.layer(l).links[p.index(x, y)];
    links = SetLink(links, d, to);
  };
  link(kFront, 1, 0, kLeft, Link::kBack);  // B front <-> A back.
  link(kBack, 0, 0, kRight, Link::kFront);
  link(kFront, 1, 0, kDown, Link::kFront);  // B front <-> D front.
  link(kFront, 1, 1, kUp, Link::kFront);
  return p;
}

TEST(MeshBuilderTest, CrossLayerTriangleTakesTheHalfWithFewerWrongVertices) {
  for (bool back_at_d : {false, true}) {
    SCOPED_TRACE(back_at_d ? "back node at D" : "no back node at D");
    const TwoLayerPanorama p = CrossLayerQuad(back_at_d);
    ASSERT_TRUE(p.Validate().ok()) << p.Validate().ToString();
    auto mesh = BuildMesh(p);
    ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
    ASSERT_EQ(mesh->num_triangles(), 1u);
    ASSERT_EQ(mesh->num_vertices(), 3u);
    CheckTriangles(p, *mesh);
    // Back half: B front is wrong (a back node at B); front half: A back is
    // wrong (a front node at A), and D front too if D has a back node. A tie
    // takes the back half.
    const int want_half = back_at_d ? kFront : kBack;
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(NodeOfVertex(p, *mesh, mesh->indices[k]).half, want_half);
    }
    EXPECT_EQ(CountVerticesWithOtherAtlasColor(p, *mesh), 1);
  }
}

TEST(MeshBuilderTest, ProceduralRoomMeshIsConsistentAndDeterministic) {
  const TwoLayerPanorama p = testing::MakeRoomPanorama(96, 48);
  auto a = BuildMesh(p);
  auto b = BuildMesh(p);
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(a->positions, b->positions);
  EXPECT_EQ(a->indices, b->indices);
  EXPECT_EQ(a->uvs, b->uvs);
  CheckTriangles(p, *a);
  // Back nodes exist only behind the sphere, so every front node joined to
  // a back node sits where the back half shows its own colour.
  EXPECT_EQ(CountVerticesWithOtherAtlasColor(p, *a), 0);
  // Nearly every quad is closed by the front or back sheet; the sphere adds its own.
  EXPECT_GT(a->num_triangles(), 2u * 96 * 47);
  EXPECT_LT(a->num_triangles(), 2u * 96 * 47 + 400);
  // No triangle spans a depth edge: along each edge depths differ by < 25 %,
  // diagonals included (they join two nodes linked through a third).
  for (size_t t = 0; t < a->num_triangles(); ++t) {
    float d[3];
    for (int k = 0; k < 3; ++k) {
      const float* q = &a->positions[3 * a->indices[3 * t + k]];
      d[k] = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    }
    for (int k = 0; k < 3; ++k) {
      EXPECT_GT(std::min(d[k], d[(k + 1) % 3]) / std::max(d[k], d[(k + 1) % 3]), 0.56f);
    }
  }
}

TEST(MeshBuilderTest, DeterministicSinCosMatchesLibm) {
  double max_err = 0;
  for (int k = -40000; k <= 40000; ++k) {
    const double a = k * (4.0 * kPi / 40000);
    double s, c;
    DeterministicSinCos(a, &s, &c);
    max_err = std::max(max_err, std::max(std::fabs(s - std::sin(a)), std::fabs(c - std::cos(a))));
  }
  EXPECT_LT(max_err, 1e-15);
}

TEST(MeshBuilderTest, RefusesBadInput) {
  TwoLayerPanorama p = FrontOnly(8, 4, [](int, int) { return 2.0f; });
  MeshBuildOptions small;
  small.max_pixels = 31;
  auto r = BuildMesh(p, small);
  EXPECT_EQ(r.status().code(), StatusCode::kLimitExceeded);
  EXPECT_EQ(r.status().message(),
            "panorama 8x4 has 32 pixels, more than the mesh builder's limit of 31");

  MeshBuildOptions bad;
  bad.max_pixels = 0;
  EXPECT_EQ(BuildMesh(p, bad).status().code(), StatusCode::kInvalidArgument);

  p.layer(kFront).depth_m[3] = -1.0f;
  EXPECT_EQ(BuildMesh(p).status().code(), StatusCode::kInvalidData);

  EXPECT_EQ(BuildMesh(TwoLayerPanorama(1, 4)).status().code(), StatusCode::kInvalidArgument);

  MeshBuildOptions unchecked;
  unchecked.validate_input = false;
  TwoLayerPanorama broken(8, 4);
  broken.layer(kBack).links.resize(3);
  EXPECT_EQ(BuildMesh(broken, unchecked).status().code(), StatusCode::kInvalidData);
}

TEST(MeshBuilderTest, EmptyAndSingleRowPanoramasGiveEmptyMeshes) {
  auto empty = BuildMesh(TwoLayerPanorama(8, 4));
  ASSERT_TRUE(empty.ok());
  EXPECT_EQ(empty->num_vertices(), 0u);
  EXPECT_EQ(empty->num_triangles(), 0u);
  auto row = BuildMesh(FrontOnly(8, 1, [](int, int) { return 1.0f; }));
  ASSERT_TRUE(row.ok());
  EXPECT_EQ(row->num_triangles(), 0u);
}

// Pins the exact output (every float bit, every index). The Emscripten build
// gives the same checksum; a change here is a change of spec/mesh.md's output.
TEST(MeshBuilderTest, GoldenChecksum) {
  auto mesh = BuildMesh(testing::MakeBlocksPanorama());
  ASSERT_TRUE(mesh.ok());
  EXPECT_EQ(mesh->num_triangles(), 309166u);
  EXPECT_EQ(mesh->num_vertices(), 159715u);  // 2835 atlas-half copies.
  EXPECT_EQ(testing::MeshChecksum(*mesh), 0x826f4abbec0b7206ull);
}

// MeshAssembler::Finish marks, numbers and writes vertices on several
// threads: the mesh must be the same for any number of them.
TEST(MeshBuilderTest, SameMeshForEveryThreadCount) {
  const TwoLayerPanorama p = testing::MakeBlocksPanorama();
  MeshBuildOptions o;
  o.num_threads = 1;
  auto one = BuildMesh(p, o);
  ASSERT_TRUE(one.ok());
  for (int threads : {2, 3, 7}) {
    o.num_threads = threads;
    auto many = BuildMesh(p, o);
    ASSERT_TRUE(many.ok());
    EXPECT_EQ(testing::MeshChecksum(*many), testing::MeshChecksum(*one)) << threads;
    EXPECT_EQ(many->indices, one->indices);
    EXPECT_EQ(many->normals, one->normals);
  }
  o.num_threads = 300;
  EXPECT_EQ(BuildMesh(p, o).status().message(), "num_threads 300 is outside [0, 256]");
}

}  // namespace
}  // namespace casual3d
