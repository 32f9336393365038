#include "reconstruct/synth/primitives.h"

#include <cmath>

#include <gtest/gtest.h>

#include "reconstruct/synth/procedural_texture.h"
#include "reconstruct/synth/scene.h"

namespace casual3d::synth {
namespace {

using Eigen::Vector3d;

TEST(PrimitivesTest, SphereInterval) {
  const Primitive s = MakeSphere({0, 0, -5}, 1.0, 0);
  Interval iv;
  ASSERT_TRUE(IntersectPrimitive(s, {0, 0, 0}, {0, 0, -1}, &iv));
  EXPECT_NEAR(iv.t_in, 4.0, 1e-12);
  EXPECT_NEAR(iv.t_out, 6.0, 1e-12);
  EXPECT_FALSE(IntersectPrimitive(s, {0, 0, 0}, {0, 0, 1}, &iv));  // Behind.
  EXPECT_FALSE(IntersectPrimitive(s, {0, 1.01, 0}, {0, 0, -1}, &iv));
  const Vector3d n = PrimitiveNormal(s, {0, 0, -4}, 0);
  EXPECT_NEAR(n.z(), 1.0, 1e-12);
}

TEST(PrimitivesTest, RotatedBoxIntervalAndFaces) {
  const Primitive b = MakeBox({0, 0, -10}, {1, 2, 3}, 90.0, 0);  // Local x along world -z.
  Interval iv;
  ASSERT_TRUE(IntersectPrimitive(b, {0, 0, 0}, {0, 0, -1}, &iv));
  EXPECT_NEAR(iv.t_in, 9.0, 1e-9);
  EXPECT_NEAR(iv.t_out, 11.0, 1e-9);
  const Vector3d n = PrimitiveNormal(b, {0, 0, -9}, iv.face_in);
  EXPECT_NEAR(n.dot(Vector3d(0, 0, 1)), 1.0, 1e-9);
  // From the side: the local z half extent (3) now lies along world x.
  ASSERT_TRUE(IntersectPrimitive(b, {-10, 0, -10}, {1, 0, 0}, &iv));
  EXPECT_NEAR(iv.t_in, 7.0, 1e-9);
  Vector3d lo, hi;
  PrimitiveBounds(b, &lo, &hi);
  EXPECT_NEAR(lo.x(), -3, 1e-9);
  EXPECT_NEAR(hi.z(), -9, 1e-9);
}

TEST(PrimitivesTest, SlantedCylinderSideAndCaps) {
  const Primitive c = MakeCylinder({0, 0, -4}, {0, 2, -4}, 0.5, 0);
  Interval iv;
  ASSERT_TRUE(IntersectPrimitive(c, {0, 1, 0}, {0, 0, -1}, &iv));
  EXPECT_NEAR(iv.t_in, 3.5, 1e-9);
  EXPECT_NEAR(iv.t_out, 4.5, 1e-9);
  EXPECT_EQ(iv.face_in, 0);
  // Straight down onto the top cap.
  ASSERT_TRUE(IntersectPrimitive(c, {0.2, 5, -4}, {0, -1, 0}, &iv));
  EXPECT_NEAR(iv.t_in, 3.0, 1e-9);
  EXPECT_NEAR(iv.t_out, 5.0, 1e-9);
  EXPECT_NEAR(PrimitiveNormal(c, {0.2, 2, -4}, iv.face_in).y(), 1.0, 1e-9);
  EXPECT_FALSE(IntersectPrimitive(c, {0, 2.5, 0}, {0, 0, -1}, &iv));  // Above the top.
  // A 45-degree rod, hit perpendicular to its axis.
  const Primitive rod = MakeCylinder({-1, -1, -2}, {1, 1, -2}, 0.01, 0);
  ASSERT_TRUE(IntersectPrimitive(rod, {0, 0, 0}, {0, 0, -1}, &iv));
  EXPECT_NEAR(iv.t_in, 1.99, 1e-9);
}

TEST(SceneTest, SecondSurfaceSkipsHiddenInsides) {
  // A box standing on (and sunk into) the ground slab, a wall behind it.
  std::vector<Primitive> prims = {
      MakeBox({0, -0.5, 0}, {50, 0.5, 50}, 0, 0),    // Ground, top at y = 0.
      MakeBox({0, 0.49, -3}, {0.5, 0.5, 0.5}, 0, 0),  // Box on the ground, front face z = -2.5.
      MakeBox({0, 2, -10}, {5, 2, 0.1}, 0, 0),       // Wall, front face z = -9.9.
      MakeBox({0, 0.5, 5}, {0.2, 0.2, 0.2}, 0, 0),   // A small box behind the origin.
  };
  prims[0].is_ground = true;
  Material m;
  const Scene scene(prims, {m});
  Hit first, second;
  bool into_ground = false;
  // Looking down onto the top of the box: the ground below it is inside the
  // union (box sunk into the slab), so there is no second surface.
  ASSERT_EQ(scene.TraceTwoSurfaces({0, 2, -3}, {0, -1, 0}, &first, &second, &into_ground), 1);
  EXPECT_TRUE(into_ground);
  EXPECT_EQ(first.primitive, 1);
  EXPECT_NEAR(first.t, 2.0 - 0.99, 1e-9);
  // Horizontal through the box: first the box, then the wall.
  ASSERT_EQ(scene.TraceTwoSurfaces({0, 0.5, 0}, {0, 0, -1}, &first, &second, &into_ground), 2);
  EXPECT_EQ(first.primitive, 1);
  EXPECT_NEAR(first.t, 2.5, 1e-9);
  EXPECT_EQ(second.primitive, 2);
  EXPECT_NEAR(second.t, 9.9, 1e-9);
  // The same closest hit as TraceClosest.
  Hit closest;
  ASSERT_TRUE(scene.TraceClosest({0, 0.5, 0}, {0, 0, -1}, 1e-9, &closest));
  EXPECT_EQ(closest.primitive, 1);
  // Upwards: sky.
  EXPECT_EQ(scene.TraceTwoSurfaces({0, 0.5, 0}, {0, 1, 0}, &first, &second, &into_ground), 0);
  // Through the small box behind into the sky: one surface, then the open.
  ASSERT_EQ(scene.TraceTwoSurfaces({0, 0.5, 0}, {0, 0, 1}, &first, &second, &into_ground), 1);
  EXPECT_FALSE(into_ground);
  EXPECT_EQ(first.primitive, 0 + 3);
  // Onto the ground in front of the box: nothing behind the ground.
  ASSERT_EQ(scene.TraceTwoSurfaces({0, 0.5, 0}, Eigen::Vector3d(0, -1, -1).normalized(), &first,
                                   &second, &into_ground), 1);
  EXPECT_TRUE(into_ground);
  EXPECT_EQ(first.primitive, 0);
  EXPECT_FALSE(scene.TraceClosest({0, 0.5, 0}, {0, 1, 0}, 1e-9, &closest));
}

TEST(SceneTest, BvhAgreesWithBruteForce) {
  std::vector<Primitive> prims;
  for (int i = 0; i < 60; ++i) {
    const double a = HashToUnit(Hash(i, 1)) * 20 - 10, b = HashToUnit(Hash(i, 2)) * 20 - 10;
    const double c = HashToUnit(Hash(i, 3)) * 4;
    if (i % 3 == 0) prims.push_back(MakeSphere({a, c, b}, 0.5, 0));
    if (i % 3 == 1) prims.push_back(MakeBox({a, c, b}, {0.4, 0.7, 0.3}, 17.0 * i, 0));
    if (i % 3 == 2) prims.push_back(MakeCylinder({a, 0, b}, {a + 0.3, c + 1, b}, 0.1, 0));
  }
  const Scene scene(prims, {Material()});
  int hits = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vector3d dir = Vector3d(HashToNormal(Hash(k, 4), Hash(k, 5)), HashToNormal(Hash(k, 6), Hash(k, 7)),
                                  HashToNormal(Hash(k, 8), Hash(k, 9)))
                             .normalized();
    const Vector3d origin(0, 1.5, 0);
    double best = 1e300;
    int best_p = -1;
    for (size_t p = 0; p < prims.size(); ++p) {
      Interval iv;
      if (IntersectPrimitive(prims[p], origin, dir, &iv) && iv.t_in > 1e-9 && iv.t_in < best) {
        best = iv.t_in;
        best_p = static_cast<int>(p);
      }
    }
    Hit hit;
    const bool found = scene.TraceClosest(origin, dir, 1e-9, &hit);
    ASSERT_EQ(found, best_p >= 0) << k;
    if (found) {
      ++hits;
      EXPECT_EQ(hit.primitive, best_p);
      EXPECT_DOUBLE_EQ(hit.t, best);
    }
  }
  EXPECT_GT(hits, 100);
}

TEST(ProceduralTextureTest, NoiseIsDeterministicBoundedAndBandLimited) {
  const Vector3d p(0.3, 1.7, -2.2);
  EXPECT_EQ(FractalNoise(p, 4.0, 6, 0.6, 0.001, 7), FractalNoise(p, 4.0, 6, 0.6, 0.001, 7));
  EXPECT_NE(FractalNoise(p, 4.0, 6, 0.6, 0.001, 7), FractalNoise(p, 4.0, 6, 0.6, 0.001, 8));
  // A footprint larger than every wavelength leaves only the mean.
  EXPECT_DOUBLE_EQ(FractalNoise(p, 4.0, 6, 0.6, 10.0, 7), 0.5);
  for (int i = 0; i < 1000; ++i) {
    const double v = ValueNoise3(Vector3d(i * 0.37, i * 0.11, -i * 0.05), 3);
    ASSERT_GE(v, 0.0);
    ASSERT_LE(v, 1.0);
  }
  // A box-filtered pulse averages to its duty cycle over a wide footprint.
  EXPECT_NEAR(FilteredPulse(0.123, 1.0, 0.3, 5.0), 0.3, 1e-12);
  EXPECT_DOUBLE_EQ(FilteredPulse(0.1, 1.0, 0.3, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(FilteredPulse(0.5, 1.0, 0.3, 0.0), 0.0);
  EXPECT_NEAR(FilteredPulse(0.3, 1.0, 0.3, 0.2), 0.5, 1e-12);  // Centred on the edge.
}

}  // namespace
}  // namespace casual3d::synth
