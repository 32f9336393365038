#include "reconstruct/render/mesh_renderer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <string>

namespace casual3d::render {
namespace {

// ---------------------------------------------------------------------------
// Helpers.

void AddVertex(Mesh* mesh, const Eigen::Vector3d& p, double u, double v,
               const uint8_t rgb[3] = nullptr) {
  for (int k = 0; k < 3; ++k) mesh->positions.push_back(static_cast<float>(p[k]));
  mesh->normals.insert(mesh->normals.end(), {0.f, 0.f, 0.f});
  mesh->uvs.push_back(static_cast<float>(u));
  mesh->uvs.push_back(static_cast<float>(v));
  for (int k = 0; k < 3; ++k) mesh->colors.push_back(rgb ? rgb[k] : 0);
}

void AddTriangle(Mesh* mesh, uint32_t a, uint32_t b, uint32_t c) {
  mesh->indices.insert(mesh->indices.end(), {a, b, c});
}

// An atlas whose colour is linear in the texel index, so that bilinear
// filtering reproduces the linear function exactly away from the borders:
// R = 2 x + 40, G = 3 y + 10, B = 77.
Image8 LinearAtlas(int width, int height) {
  Image8 atlas(width, height, 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      atlas.at(x, y, 0) = static_cast<uint8_t>(2 * x + 40);
      atlas.at(x, y, 1) = static_cast<uint8_t>(3 * y + 10);
      atlas.at(x, y, 2) = 77;
    }
  }
  return atlas;
}

// The camera-frame ray (x, y, 1) through the centre of pixel (i, j).
Eigen::Vector3d PixelRay(const PinholeView& view, int i, int j) {
  return {(i + 0.5 - view.cx) / view.fx, (j + 0.5 - view.cy) / view.fy, 1.0};
}

// The same ray in the panorama frame (not normalized), from the eye.
Eigen::Vector3d PanoramaRay(const PinholeView& view, int i, int j) {
  return view.rotation.transpose() * PixelRay(view, i, j);
}

Eigen::Vector3d Eye(const PinholeView& view) {
  return -(view.rotation.transpose() * view.translation);
}

// A parallelogram O + s E1 + t E2 (s, t in [0, 1]) textured with uv =
// (0.25 + 0.5 s, 0.25 + 0.5 t), as two triangles.
Mesh Parallelogram(const Eigen::Vector3d& o, const Eigen::Vector3d& e1, const Eigen::Vector3d& e2) {
  Mesh mesh;
  AddVertex(&mesh, o, 0.25, 0.25);
  AddVertex(&mesh, o + e1, 0.75, 0.25);
  AddVertex(&mesh, o + e1 + e2, 0.75, 0.75);
  AddVertex(&mesh, o + e2, 0.25, 0.75);
  AddTriangle(&mesh, 0, 1, 2);
  AddTriangle(&mesh, 0, 2, 3);
  return mesh;
}

// Renders a parallelogram and compares every pixel with the analytic
// ray-plane intersection: coverage, depth, and the colour of the linear atlas
// at the exact uv. Returns the largest colour error.
double CheckParallelogram(const Eigen::Vector3d& o, const Eigen::Vector3d& e1,
                          const Eigen::Vector3d& e2, const GlCamera& camera, int width, int height,
                          int* covered) {
  const Mesh mesh = Parallelogram(o, e1, e2);
  const Image8 atlas = LinearAtlas(64, 64);
  const PinholeView view = ViewFromGlCamera(camera, width, height);
  const RenderResult r = RenderMesh(mesh, atlas.view(), view);
  double max_color_error = 0.0;
  int mismatched_coverage = 0, near_edge = 0;
  *covered = 0;
  for (int j = 0; j < height; ++j) {
    for (int i = 0; i < width; ++i) {
      // Solve eye + lambda d = o + s e1 + t e2.
      Eigen::Matrix3d m;
      m.col(0) = PanoramaRay(view, i, j);
      m.col(1) = -e1;
      m.col(2) = -e2;
      const Eigen::Vector3d x = m.colPivHouseholderQr().solve(o - Eye(view));
      const double lambda = x[0], s = x[1], t = x[2];
      const double band = 2e-4;
      const bool inside = lambda > 0 && s > band && s < 1 - band && t > band && t < 1 - band;
      const bool outside = lambda <= 0 || s < -band || s > 1 + band || t < -band || t > 1 + band;
      const bool got = r.mask.at(i, j) == 255;
      if ((inside && !got) || (outside && got)) ++mismatched_coverage;
      if (!inside && !outside) ++near_edge;
      if (!got || !inside) continue;
      ++*covered;
      // Depth is camera-frame z, which is lambda for a ray with z = 1.
      EXPECT_NEAR(r.depth.at(i, j), lambda, 1e-5 * lambda) << i << "," << j;
      const double u = 0.25 + 0.5 * s, v = 0.25 + 0.5 * t;
      const double want_r = 2.0 * (u * 64 - 0.5) + 40, want_g = 3.0 * (v * 64 - 0.5) + 10;
      max_color_error = std::max(max_color_error, std::abs(r.color.at(i, j, 0) - want_r));
      max_color_error = std::max(max_color_error, std::abs(r.color.at(i, j, 1) - want_g));
      EXPECT_EQ(r.color.at(i, j, 2), 77);
    }
  }
  EXPECT_EQ(mismatched_coverage, 0);
  // Pixel centres within 1/5000 of the quad's size from its border are not
  // checked; there are few.
  EXPECT_LE(near_edge, 20);
  EXPECT_LE(r.covered_pixels - *covered, near_edge);
  return max_color_error;
}

// ---------------------------------------------------------------------------
// Views.

TEST(MeshRendererTest, GlCameraConventions) {
  GlCamera camera;
  camera.fov_y_deg = 90.0;
  const PinholeView view = ViewFromGlCamera(camera, 200, 100);
  EXPECT_DOUBLE_EQ(view.fy, 50.0);  // (height / 2) / tan(45 deg)
  EXPECT_DOUBLE_EQ(view.fx, 50.0);  // square pixels
  EXPECT_DOUBLE_EQ(view.cx, 100.0);
  EXPECT_DOUBLE_EQ(view.cy, 50.0);
  // spec/projection.md Sec. 3.1: looking forward upright, x_cam = diag(1, -1, -1) p.
  EXPECT_NEAR((view.rotation - Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix()).norm(), 0,
              1e-15);
  auto project = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d c = view.rotation * p + view.translation;
    return Eigen::Vector3d(view.fx * c.x() / c.z() + view.cx, view.fy * c.y() / c.z() + view.cy,
                           c.z());
  };
  // Forward (-Z) is the image centre at depth 2; up (+Y) is the top row;
  // right (+X) is to the right.
  EXPECT_TRUE(project({0, 0, -2}).isApprox(Eigen::Vector3d(100, 50, 2)));
  EXPECT_TRUE(project({0, 1, -1}).isApprox(Eigen::Vector3d(100, 0, 1)));
  EXPECT_TRUE(project({1, 0, -1}).isApprox(Eigen::Vector3d(150, 50, 1)));

  // yaw 90 looks along +X; pitch 90 - epsilon looks nearly straight up.
  camera.yaw_deg = 90.0;
  camera.position[0] = 1.0;
  const PinholeView right = ViewFromGlCamera(camera, 200, 100);
  const Eigen::Vector3d c = right.rotation * Eigen::Vector3d(4, 0, 0) + right.translation;
  EXPECT_NEAR(c.x(), 0, 1e-12);
  EXPECT_NEAR(c.y(), 0, 1e-12);
  EXPECT_NEAR(c.z(), 3, 1e-12);
  // Looking along +X, +Z (behind the panorama's forward) is on the right.
  EXPECT_GT((right.rotation * Eigen::Vector3d(4, 0, 1) + right.translation).x(), 0);

  camera.pitch_deg = 90.0;
  EXPECT_THROW(ViewFromGlCamera(camera, 200, 100), std::invalid_argument);
  camera.pitch_deg = 0.0;
  camera.fov_y_deg = 180.0;
  EXPECT_THROW(ViewFromGlCamera(camera, 200, 100), std::invalid_argument);
}

TEST(MeshRendererTest, PhotoViewEqualsEquivalentGlView) {
  // A viewer camera in the panorama frame and the same camera expressed as a
  // COLMAP photo in a world related to the panorama by a non-trivial frame.
  GlCamera gl;
  gl.position[0] = 0.1;
  gl.position[1] = -0.05;
  gl.position[2] = 0.2;
  gl.yaw_deg = 10.0;
  gl.pitch_deg = -5.0;
  gl.fov_y_deg = 60.0;
  const PinholeView want = ViewFromGlCamera(gl, 320, 240);

  PanoramaFrame frame;
  const Eigen::Matrix3d F =
      Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d centre(3.0, -1.0, 7.5);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) frame.rotation[3 * r + c] = F(r, c);
    frame.centre[r] = centre[r];
  }
  geometry::Camera camera;
  camera.model = geometry::CameraModelId::kSimpleRadial;
  camera.width = 320;
  camera.height = 240;
  camera.params = {want.fx, want.cx, want.cy, 0.05};  // Distortion is ignored.
  const Eigen::Vector3d eye(gl.position[0], gl.position[1], gl.position[2]);
  const geometry::Pose pose =
      geometry::Pose::FromCenter(want.rotation * F, F.transpose() * eye + centre);
  const PinholeView got = ViewFromPhoto(camera, pose, frame);
  EXPECT_NEAR((got.rotation - want.rotation).norm(), 0.0, 1e-12);
  EXPECT_NEAR((got.translation - want.translation).norm(), 0.0, 1e-12);
  EXPECT_EQ(got.width, 320);
  EXPECT_EQ(got.height, 240);
  EXPECT_DOUBLE_EQ(got.fx, want.fx);
  EXPECT_DOUBLE_EQ(got.cy, want.cy);
}

// ---------------------------------------------------------------------------
// Rasterization against analytic scenes.

TEST(MeshRendererTest, FrontalTexturedQuad) {
  // A 2 m square, 2 m in front of the eye, seen with a 90 degree field of
  // view on a 101 x 101 image: it spans pixel coordinates 50.5 +- 25.25, so
  // pixel centres 25.5 ... 75.5, i.e. exactly 51 x 51 pixels.
  GlCamera camera;
  camera.fov_y_deg = 90.0;
  int covered = 0;
  const double error =
      CheckParallelogram({-1, 1, -2}, {2, 0, 0}, {0, -2, 0}, camera, 101, 101, &covered);
  EXPECT_EQ(covered, 51 * 51);
  EXPECT_LE(error, 0.75);
}

TEST(MeshRendererTest, TiltedQuadIsPerspectiveCorrect) {
  // A quad receding from 1.2 m to 4.2 m: affine (non-perspective) uv
  // interpolation would be off by tens of colour levels in the middle.
  GlCamera camera;
  camera.fov_y_deg = 100.0;
  camera.yaw_deg = 8.0;
  camera.pitch_deg = -12.0;
  int covered = 0;
  const double error =
      CheckParallelogram({-1, 1, -1.2}, {2, 0, 0}, {0, -2, -3}, camera, 160, 120, &covered);
  EXPECT_GT(covered, 3000);
  EXPECT_LE(error, 0.75);
}

TEST(MeshRendererTest, BackFacesAreDrawnAndNothingBehindTheEye) {
  GlCamera camera;
  camera.fov_y_deg = 90.0;
  int covered = 0;
  // The same quad with the opposite winding.
  CheckParallelogram({-1, 1, -2}, {0, -2, 0}, {2, 0, 0}, camera, 101, 101, &covered);
  EXPECT_EQ(covered, 51 * 51);
  // Turned around, the quad is behind the eye: nothing is drawn.
  camera.yaw_deg = 180.0;
  const Image8 atlas = LinearAtlas(64, 64);
  const RenderResult r = RenderMesh(Parallelogram({-1, 1, -2}, {2, 0, 0}, {0, -2, 0}), atlas.view(),
                                    ViewFromGlCamera(camera, 101, 101));
  EXPECT_EQ(r.covered_pixels, 0);
  EXPECT_EQ(r.depth.at(50, 50), 0.0f);
  EXPECT_EQ(r.color.at(50, 50, 0), 0);
}

TEST(MeshRendererTest, NearPlaneClipsAFloorThatPassesUnderTheEye) {
  // A 100 m floor 1 m below the eye, reaching 50 m behind it: its far corners
  // project through the eye, so without clipping the triangles would flip.
  Mesh floor = Parallelogram({-50, -1, 50}, {100, 0, 0}, {0, 0, -100});
  for (uint8_t& c : floor.colors) c = 90;
  GlCamera camera;
  camera.pitch_deg = -30.0;
  camera.fov_y_deg = 90.0;
  const PinholeView view = ViewFromGlCamera(camera, 120, 90);
  RenderOptions options;
  options.color_source = ColorSource::kVertexColors;
  options.near_m = 0.05;
  const RenderResult r = RenderMesh(floor, {}, view, options);
  int checked = 0, mismatched = 0;
  for (int j = 0; j < 90; ++j) {
    for (int i = 0; i < 120; ++i) {
      const Eigen::Vector3d d = PanoramaRay(view, i, j);
      // Hit of the plane y = -1 (the eye is at the origin).
      const double lambda = d.y() < 0 ? -1.0 / d.y() : -1.0;
      const Eigen::Vector3d hit = lambda * d;
      const bool expected = lambda > 0 && std::abs(hit.x()) < 50 && std::abs(hit.z()) < 50;
      const bool got = r.mask.at(i, j) == 255;
      if (expected != got) {
        ++mismatched;
        continue;
      }
      if (!got) continue;
      ++checked;
      EXPECT_NEAR(r.depth.at(i, j), lambda, 1e-4 * lambda);
      EXPECT_EQ(r.color.at(i, j, 1), 90);
    }
  }
  EXPECT_GT(checked, 4000);
  // Only the pixels straddling the floor's far edge may differ.
  EXPECT_LE(mismatched, 120);
}

TEST(MeshRendererTest, NearAndFarPlanesCutGeometry) {
  const Mesh quad = Parallelogram({-1, 1, -2}, {2, 0, 0}, {0, -2, 0});
  const Image8 atlas = LinearAtlas(8, 8);
  GlCamera camera;
  camera.fov_y_deg = 90.0;
  RenderOptions options;
  options.far_m = 1.5;
  EXPECT_EQ(
      RenderMesh(quad, atlas.view(), ViewFromGlCamera(camera, 51, 51), options).covered_pixels, 0);
  options.far_m = 2000.0;
  options.near_m = 2.5;
  EXPECT_EQ(
      RenderMesh(quad, atlas.view(), ViewFromGlCamera(camera, 51, 51), options).covered_pixels, 0);
}

// A unit cube (side 1 m) with one colour per face, centred at `center`.
Mesh ColoredCube(const Eigen::Vector3d& center) {
  Mesh mesh;
  const uint8_t colors[6][3] = {{255, 0, 0},   {0, 255, 0},   {0, 0, 255},
                                {255, 255, 0}, {0, 255, 255}, {255, 0, 255}};
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const int face = 2 * axis + side;
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      const uint32_t base = static_cast<uint32_t>(mesh.num_vertices());
      for (int corner = 0; corner < 4; ++corner) {
        Eigen::Vector3d p = center;
        p[axis] += side ? 0.5 : -0.5;
        p[a] += (corner == 1 || corner == 2) ? 0.5 : -0.5;
        p[b] += (corner >= 2) ? 0.5 : -0.5;
        AddVertex(&mesh, p, 0, 0, colors[face]);
      }
      AddTriangle(&mesh, base, base + 1, base + 2);
      AddTriangle(&mesh, base, base + 2, base + 3);
    }
  }
  return mesh;
}

TEST(MeshRendererTest, CubeSeenFromAPhotoMatchesRayCasting) {
  const Eigen::Vector3d center(0.3, -0.2, -3.0);
  const Mesh cube = ColoredCube(center);
  // The photo's world differs from the panorama frame.
  PanoramaFrame frame;
  const Eigen::Matrix3d F =
      Eigen::AngleAxisd(-0.6, Eigen::Vector3d(0.2, 1, 0.1).normalized()).toRotationMatrix();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) frame.rotation[3 * r + c] = F(r, c);
  }
  frame.centre[0] = 10.0;
  frame.centre[2] = -4.0;
  const Eigen::Vector3d frame_centre(10.0, 0.0, -4.0);
  auto to_world = [&](const Eigen::Vector3d& p) { return F.transpose() * p + frame_centre; };
  geometry::Camera camera;
  camera.model = geometry::CameraModelId::kPinhole;
  camera.width = 200;
  camera.height = 150;
  camera.params = {180.0, 182.0, 97.0, 76.0};
  const Eigen::Vector3d eye(1.2, 0.8, -0.5);  // Panorama frame: above, right.
  const geometry::Pose pose = geometry::Pose::LookAt(to_world(eye), to_world(center),
                                                     F.transpose() * Eigen::Vector3d::UnitY());
  const PinholeView view = ViewFromPhoto(camera, pose, frame);
  RenderOptions options;
  options.color_source = ColorSource::kVertexColors;
  const RenderResult r = RenderMesh(cube, {}, view, options);

  // Ray casting (slab method) in the panorama frame.
  const uint8_t colors[6][3] = {{255, 0, 0},   {0, 255, 0},   {0, 0, 255},
                                {255, 255, 0}, {0, 255, 255}, {255, 0, 255}};
  int hits = 0, mismatched = 0;
  for (int j = 0; j < camera.height; ++j) {
    for (int i = 0; i < camera.width; ++i) {
      const Eigen::Vector3d d = PanoramaRay(view, i, j);
      const Eigen::Vector3d o = Eye(view);
      double t_near = -1e300, t_far = 1e300;
      int face = -1;
      for (int axis = 0; axis < 3; ++axis) {
        const double t0 = (center[axis] - 0.5 - o[axis]) / d[axis];
        const double t1 = (center[axis] + 0.5 - o[axis]) / d[axis];
        const double lo = std::min(t0, t1), hi = std::max(t0, t1);
        if (lo > t_near) {
          t_near = lo;
          face = 2 * axis + (t0 < t1 ? 0 : 1);
        }
        t_far = std::min(t_far, hi);
      }
      const bool hit = t_near < t_far && t_near > 0;
      const bool got = r.mask.at(i, j) == 255;
      // Pixels within half a pixel of a silhouette or a cube edge may go
      // either way; count them and bound the total below.
      const bool same_color = got && hit && r.color.at(i, j, 0) == colors[face][0] &&
                              r.color.at(i, j, 1) == colors[face][1] &&
                              r.color.at(i, j, 2) == colors[face][2];
      if (hit != got || (hit && !same_color)) {
        ++mismatched;
        continue;
      }
      if (!hit) continue;
      ++hits;
      // The ray has camera-frame z = 1, so its parameter is the depth.
      EXPECT_NEAR(r.depth.at(i, j), t_near, 1e-5 * t_near);
    }
  }
  EXPECT_GT(hits, 2000);
  EXPECT_LT(mismatched, 12);
}

TEST(MeshRendererTest, SharedEdgesLeaveNoCracks) {
  // A 40 x 40 grid on a plane with jittered interior vertices and random
  // diagonals: every pixel centre inside the outer square must be covered.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.4, 0.4);
  const int n = 40;
  const double cell = 2.0 / n;
  Mesh mesh;
  for (int y = 0; y <= n; ++y) {
    for (int x = 0; x <= n; ++x) {
      double px = -1 + x * cell, py = 1 - y * cell;
      if (x > 0 && x < n && y > 0 && y < n) {
        px += jitter(rng) * cell;
        py += jitter(rng) * cell;
      }
      const uint8_t c[3] = {200, 100, 50};
      AddVertex(&mesh, {px, py, -2.0}, 0, 0, c);
    }
  }
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      if (rng() % 2) {
        AddTriangle(&mesh, a, b, d);
        AddTriangle(&mesh, a, d, c);
      } else {
        AddTriangle(&mesh, a, b, c);
        AddTriangle(&mesh, b, d, c);
      }
    }
  }
  GlCamera camera;
  camera.fov_y_deg = 90.0;
  RenderOptions options;
  options.color_source = ColorSource::kVertexColors;
  const RenderResult r = RenderMesh(mesh, {}, ViewFromGlCamera(camera, 203, 203), options);
  // The square spans 101.5 +- 50.75 pixels: centres 51.5 ... 151.5.
  int holes = 0;
  for (int j = 51; j <= 151; ++j) {
    for (int i = 51; i <= 151; ++i) holes += r.mask.at(i, j) != 255;
  }
  EXPECT_EQ(holes, 0);
  EXPECT_EQ(r.covered_pixels, 101 * 101);
}

TEST(MeshRendererTest, TopLeftRuleCoversPixelsOnSharedEdgesOnce) {
  // A square split into four triangles around its centre, with every vertex
  // exactly on a pixel centre, so that all edges (including the diagonals)
  // pass through pixel centres. Rendering the triangles one by one must cover
  // as many pixels in total as rendering them together, and the square covers
  // centres 20.5 <= x < 60.5 (left and top edges in, right and bottom out).
  GlCamera camera;
  camera.fov_y_deg = 90.0;
  const PinholeView view = ViewFromGlCamera(camera, 100, 100);  // f = 50, c = 50.
  auto at_pixel = [](double sx, double sy) {
    return Eigen::Vector3d((sx - 50.0) / 50.0, -(sy - 50.0) / 50.0, -1.0);
  };
  Mesh square;
  const uint8_t c[3] = {10, 20, 30};
  AddVertex(&square, at_pixel(20.5, 20.5), 0, 0, c);
  AddVertex(&square, at_pixel(60.5, 20.5), 0, 0, c);
  AddVertex(&square, at_pixel(60.5, 60.5), 0, 0, c);
  AddVertex(&square, at_pixel(20.5, 60.5), 0, 0, c);
  AddVertex(&square, at_pixel(40.5, 40.5), 0, 0, c);
  RenderOptions options;
  options.color_source = ColorSource::kVertexColors;
  int64_t sum = 0;
  for (uint32_t k = 0; k < 4; ++k) {
    Mesh one = square;
    one.indices = {k, (k + 1) % 4, 4};
    sum += RenderMesh(one, {}, view, options).covered_pixels;
    AddTriangle(&square, k, (k + 1) % 4, 4);
  }
  const RenderResult all = RenderMesh(square, {}, view, options);
  EXPECT_EQ(all.covered_pixels, 40 * 40);
  EXPECT_EQ(sum, all.covered_pixels);
  EXPECT_EQ(all.mask.at(20, 20), 255);  // Top-left corner: in.
  EXPECT_EQ(all.mask.at(60, 40), 0);    // Right edge: out.
  EXPECT_EQ(all.mask.at(40, 60), 0);    // Bottom edge: out.
  EXPECT_FLOAT_EQ(all.depth.at(40, 40), 1.0f);
}

// ---------------------------------------------------------------------------
// The 3D photo case: a sphere around the eye shows the equirect texture.

// Smooth colour of a direction, to fill the test panorama.
Eigen::Vector3d DirectionColor(const Eigen::Vector3d& d) {
  return Eigen::Vector3d::Constant(127.5) + 100.0 * d.normalized();
}

TEST(MeshRendererTest, SphereAroundTheEyeReproducesTheEquirectTexture) {
  const int tex_w = 512, tex_h = 256;
  // Atlas: the front panorama above a (black) back panorama, as in mesh.h.
  Image8 texture(tex_w, 2 * tex_h, 3, 0);
  for (int y = 0; y < tex_h; ++y) {
    for (int x = 0; x < tex_w; ++x) {
      const Vec3d d = EquirectPixelToDirection(x + 0.5, y + 0.5, tex_w, tex_h);
      const Eigen::Vector3d c = DirectionColor({d.x, d.y, d.z});
      for (int k = 0; k < 3; ++k) texture.at(x, y, k) = static_cast<uint8_t>(std::lround(c[k]));
    }
  }
  const Image8& atlas = texture;
  // A latitude-longitude sphere of radius 5 m with grid corners at the
  // panorama's pixel-grid lines every 2 texels.
  const double radius = 5.0;
  const int cols = 256, rows = 128;
  Mesh mesh;
  for (int r = 0; r <= rows; ++r) {
    for (int c = 0; c <= cols; ++c) {
      const double u = static_cast<double>(c) / cols, v = static_cast<double>(r) / rows;
      const Vec3d d = EquirectPixelToDirection(u * tex_w, v * tex_h, tex_w, tex_h);
      AddVertex(&mesh, radius * Eigen::Vector3d(d.x, d.y, d.z), u, v * 0.5);
    }
  }
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const uint32_t a = r * (cols + 1) + c, b = a + 1, d = a + cols + 1, e = d + 1;
      AddTriangle(&mesh, a, d, b);
      AddTriangle(&mesh, b, d, e);
    }
  }
  struct ViewCase {
    double yaw, pitch;
  };
  // Forward, right and up, behind-left and down, the seam, and the zenith
  // (the nadir would sample the back layer below the front one's last row).
  const ViewCase cases[] = {{0, 0}, {90, 30}, {-150, -40}, {180, 0}, {45, 60}};
  for (const ViewCase& vc : cases) {
    SCOPED_TRACE("yaw " + std::to_string(vc.yaw) + " pitch " + std::to_string(vc.pitch));
    GlCamera camera;
    camera.yaw_deg = vc.yaw;
    camera.pitch_deg = vc.pitch;
    camera.fov_y_deg = 90.0;
    const PinholeView view = ViewFromGlCamera(camera, 160, 120);
    const RenderResult r = RenderMesh(mesh, atlas.view(), view);
    ASSERT_EQ(r.covered_pixels, 160 * 120);
    double sum_error = 0.0, max_error = 0.0, max_depth_error = 0.0;
    for (int j = 0; j < 120; ++j) {
      for (int i = 0; i < 160; ++i) {
        const Eigen::Vector3d want = DirectionColor(PanoramaRay(view, i, j));
        for (int k = 0; k < 3; ++k) {
          const double e = std::abs(r.color.at(i, j, k) - want[k]);
          sum_error += e;
          max_error = std::max(max_error, e);
        }
        const double want_depth = radius / PixelRay(view, i, j).norm();
        max_depth_error =
            std::max(max_depth_error, std::abs(r.depth.at(i, j) - want_depth) / want_depth);
      }
    }
    EXPECT_LT(sum_error / (160 * 120 * 3), 0.6);
    EXPECT_LE(max_error, 2.5);
    // The polygonal sphere lies inside the true one by at most the sag of a
    // chord of pi / 128 radians: 1 - cos(pi / 256) = 7.5e-5 per direction.
    EXPECT_LT(max_depth_error, 2e-4);
  }
}

TEST(MeshRendererTest, OutputDoesNotDependOnThreadCount) {
  const Mesh cube = ColoredCube({0.1, 0.0, -2.5});
  Mesh scene = Parallelogram({-3, 2, -4}, {6, 0, 0}, {0, -4, 0});
  // Cube in front of a textured wall.
  const uint32_t offset = static_cast<uint32_t>(scene.num_vertices());
  scene.positions.insert(scene.positions.end(), cube.positions.begin(), cube.positions.end());
  scene.normals.insert(scene.normals.end(), cube.normals.begin(), cube.normals.end());
  scene.uvs.insert(scene.uvs.end(), cube.uvs.begin(), cube.uvs.end());
  scene.colors.insert(scene.colors.end(), cube.colors.begin(), cube.colors.end());
  for (uint32_t index : cube.indices) scene.indices.push_back(index + offset);
  GlCamera camera;
  camera.yaw_deg = 12.0;
  const PinholeView view = ViewFromGlCamera(camera, 333, 217);
  const Image8 atlas = LinearAtlas(64, 64);
  RenderOptions options;
  options.num_threads = 1;
  const RenderResult one = RenderMesh(scene, atlas.view(), view, options);
  options.num_threads = 3;
  const RenderResult three = RenderMesh(scene, atlas.view(), view, options);
  EXPECT_GT(one.covered_pixels, 10000);
  EXPECT_TRUE(one.color == three.color);
  EXPECT_TRUE(one.depth == three.depth);
  EXPECT_TRUE(one.mask == three.mask);
  // The cube hides the wall: its front face is nearer than the wall.
  EXPECT_NEAR(one.depth.at(166, 108), 2.0, 0.3);
}

TEST(MeshRendererTest, TriangleIdsNameTheTriangleThatWonTheDepthTest) {
  // A quad (triangles 0 and 1) at z = -4 behind a quad (triangles 2 and 3) at
  // z = -2 that covers the left half of the view.
  Mesh scene = Parallelogram({-3, 2, -4}, {6, 0, 0}, {0, -4, 0});
  const Mesh near = Parallelogram({-3, 2, -2}, {3, 0, 0}, {0, -4, 0});
  const uint32_t offset = static_cast<uint32_t>(scene.num_vertices());
  scene.positions.insert(scene.positions.end(), near.positions.begin(), near.positions.end());
  scene.normals.insert(scene.normals.end(), near.normals.begin(), near.normals.end());
  scene.uvs.insert(scene.uvs.end(), near.uvs.begin(), near.uvs.end());
  scene.colors.insert(scene.colors.end(), near.colors.begin(), near.colors.end());
  for (uint32_t index : near.indices) scene.indices.push_back(index + offset);
  GlCamera camera;
  camera.fov_y_deg = 100.0;
  const PinholeView view = ViewFromGlCamera(camera, 120, 90);
  const Image8 atlas = LinearAtlas(64, 64);
  RenderOptions options;
  const RenderResult plain = RenderMesh(scene, atlas.view(), view, options);
  EXPECT_TRUE(plain.triangle_ids.empty());
  options.want_triangle_ids = true;
  const RenderResult r = RenderMesh(scene, atlas.view(), view, options);
  ASSERT_EQ(r.triangle_ids.width(), 120);
  ASSERT_EQ(r.triangle_ids.height(), 90);
  // Asking for ids changes nothing else.
  EXPECT_TRUE(plain.color == r.color);
  EXPECT_TRUE(plain.depth == r.depth);
  int64_t near_pixels = 0;
  for (int y = 0; y < 90; ++y) {
    for (int x = 0; x < 120; ++x) {
      const uint32_t id = r.triangle_ids.at(x, y);
      if (!r.mask.at(x, y)) {
        EXPECT_EQ(id, kNoTriangle);
        continue;
      }
      ASSERT_LT(id, 4u);
      // The near quad wins wherever it is drawn, and its depth says so.
      EXPECT_EQ(id >= 2, r.depth.at(x, y) < 3.0f) << x << "," << y;
      near_pixels += id >= 2;
      // Left of the centre column only the near quad is seen.
      if (x < 59) {
        EXPECT_GE(id, 2u) << x << "," << y;
      }
    }
  }
  EXPECT_GT(near_pixels, 1000);
}

TEST(MeshRendererTest, SheetsAreLeftOutSeenFromOffTheCentreOnly) {
  // A sheet across a depth step: two corners on a surface 1 m away, one on a
  // wall 4 m away, 0.6 degrees apart seen from the centre.
  const double a = 0.01;
  Mesh sheet;
  const uint8_t grey[3] = {128, 128, 128};
  AddVertex(&sheet, {0, 0, -1}, 0.5, 0.5, grey);
  AddVertex(&sheet, {4 * std::sin(a), 0, -4 * std::cos(a)}, 0.5, 0.5, grey);
  AddVertex(&sheet, {0, std::sin(a), -std::cos(a)}, 0.5, 0.5, grey);
  AddTriangle(&sheet, 0, 1, 2);
  const Image8 atlas = LinearAtlas(8, 8);
  GlCamera camera;
  camera.fov_y_deg = 40.0;
  RenderOptions options;
  options.sheet_stretch = 4.0;
  // Seen from the centre it is drawn: nothing is stretched there.
  const RenderResult centre = RenderMesh(sheet, atlas.view(), ViewFromGlCamera(camera, 640, 480), options);
  EXPECT_GT(centre.covered_pixels, 0);
  // From 0.2 m to the side it spans about 9 degrees: left out, unless the
  // limit is 0 or the triangle belongs to the backdrop.
  camera.position[0] = 0.2;
  const PinholeView side = ViewFromGlCamera(camera, 640, 480);
  EXPECT_EQ(RenderMesh(sheet, atlas.view(), side, options).covered_pixels, 0);
  options.sheet_stretch = 0.0;
  const int64_t drawn = RenderMesh(sheet, atlas.view(), side, options).covered_pixels;
  EXPECT_GT(drawn, 200);
  options.sheet_stretch = 4.0;
  options.vertex_colors_from_triangle = 0;
  EXPECT_EQ(RenderMesh(sheet, atlas.view(), side, options).covered_pixels, drawn);
  // A limit above its stretch draws it.
  options.vertex_colors_from_triangle = UINT64_MAX;
  options.sheet_stretch = 1000.0;
  EXPECT_EQ(RenderMesh(sheet, atlas.view(), side, options).covered_pixels, drawn);
}

TEST(MeshRendererTest, RejectsInconsistentInput) {
  Mesh mesh = Parallelogram({-1, 1, -2}, {2, 0, 0}, {0, -2, 0});
  const Image8 atlas = LinearAtlas(8, 8);
  const PinholeView view = ViewFromGlCamera(GlCamera(), 10, 10);
  auto expect_error = [&](const Mesh& m, ImageView<const uint8_t> a, const PinholeView& v,
                          const RenderOptions& o, const std::string& message) {
    try {
      RenderMesh(m, a, v, o);
      ADD_FAILURE() << "no error; expected: " << message;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), message);
    }
  };
  Mesh bad_index = mesh;
  bad_index.indices[4] = 9;
  expect_error(bad_index, atlas.view(), view, {},
               "mesh: index 9 of triangle 1 is out of range (4 vertices)");
  Mesh bad_uvs = mesh;
  bad_uvs.uvs.pop_back();
  expect_error(bad_uvs, atlas.view(), view, {},
               "mesh: uvs has 7 floats for 4 vertices (need 2 each)");
  expect_error(mesh, {}, view, {},
               "colour atlas: need a non-empty RGB image, got 0x0 with 0 channels");
  RenderOptions bad_near;
  bad_near.near_m = 0.0;
  expect_error(mesh, atlas.view(), view, bad_near,
               "render options: near_m 0.000000 must be positive and finite");
  RenderOptions bad_sheets;
  bad_sheets.sheet_stretch = -1.0;
  expect_error(mesh, atlas.view(), view, bad_sheets,
               "render options: sheet_stretch -1.000000 must be finite and at least 0 (0 draws every triangle)");
  RenderOptions bad_threads;
  bad_threads.num_threads = -2;
  expect_error(mesh, atlas.view(), view, bad_threads,
               "render options: num_threads -2 is out of range [0, 256] (0 = all cores)");
  PinholeView bad_view = view;
  bad_view.width = 0;
  expect_error(mesh, atlas.view(), bad_view, {},
               "render view: image size 0x10 is out of range (1 to 16384 per side)");
  RenderOptions vertex_colors;
  vertex_colors.color_source = ColorSource::kVertexColors;
  Mesh no_colors = mesh;
  no_colors.colors.clear();
  expect_error(no_colors, {}, view, vertex_colors,
               "mesh: colors has 0 bytes for 4 vertices (need 3 each)");
}

}  // namespace
}  // namespace casual3d::render
