// The renderer on real 3D photo meshes (format/mesh_builder.h): seen from the
// panorama centre, the mesh must show the front layer's colour and depth in
// every direction, which ties the renderer, the mesh builder's uv and
// position conventions and format/equirect.h together.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "format/color_atlas.h"
#include "format/equirect.h"
#include "format/mesh_builder.h"
#include "format/testing/test_panoramas.h"
#include "reconstruct/render/mesh_renderer.h"

namespace casual3d::render {
namespace {

// Distance from the centre to the room of testing::MakeRoomPanorama (its
// default options) along unit direction `d`.
double AnalyticRoomDistance(const Eigen::Vector3d& d) {
  const double lo[3] = {-2.0, -1.5, -4.0}, hi[3] = {3.0, 2.5, 2.5};
  double t = 1e300;
  for (int k = 0; k < 3; ++k) {
    if (d[k] > 0) t = std::min(t, hi[k] / d[k]);
    if (d[k] < 0) t = std::min(t, lo[k] / d[k]);
  }
  const testing::RoomOptions room;
  const Eigen::Vector3d c(room.sphere_centre[0], room.sphere_centre[1], room.sphere_centre[2]);
  const double b = d.dot(c),
               disc = b * b - (c.squaredNorm() - room.sphere_radius_m * room.sphere_radius_m);
  if (disc >= 0 && b - std::sqrt(disc) > 0) t = std::min(t, b - std::sqrt(disc));
  return t;
}

TEST(MeshRendererPanoramaTest, RoomSeenFromTheCentreShowsTheFrontLayer) {
  const int w = 512, h = 256;
  const TwoLayerPanorama pano = testing::MakeRoomPanorama(w, h);
  const StatusOr<Mesh> mesh = BuildMesh(pano);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  const Image8 atlas = BuildColorAtlas(pano);
  const LayerData& front = pano.layer(0);

  struct ViewCase {
    double yaw, pitch;
    ColorSource source;
    double min_psnr_db;  // Against bilinear interpolation of the front nodes.
  };
  // Towards the sphere (forward, slightly down), the seam behind, a corner up
  // and right, the floor. Without depth edges in view, atlas sampling is
  // bilinear interpolation of the nodes (measured 67-68 dB); vertex colours
  // interpolate per triangle instead (measured 47.7 dB). The view with the
  // sphere has depth edges where the back layer shows between the sphere's
  // silhouette and the wall (measured 34.8 dB with the atlas, 34.3 dB with
  // vertex colours; with the atlas 32.2 dB, or 27.9 dB without the atlas's
  // fill rule, when triangles joining front and back nodes had uvs in both
  // atlas halves).
  const ViewCase cases[] = {{10, -10, ColorSource::kAtlas, 34.0},
                            {10, -10, ColorSource::kVertexColors, 32.0},
                            {180, 0, ColorSource::kAtlas, 60.0},
                            {180, 0, ColorSource::kVertexColors, 42.0},
                            {120, 35, ColorSource::kAtlas, 60.0},
                            {-70, -45, ColorSource::kAtlas, 60.0}};
  for (const ViewCase& vc : cases) {
    SCOPED_TRACE("yaw " + std::to_string(vc.yaw) + " pitch " + std::to_string(vc.pitch) +
                 (vc.source == ColorSource::kAtlas ? " atlas" : " vertex colours"));
    GlCamera camera;
    camera.yaw_deg = vc.yaw;
    camera.pitch_deg = vc.pitch;
    camera.fov_y_deg = 70.0;
    const int width = 240, height = 180;
    const PinholeView view = ViewFromGlCamera(camera, width, height);
    RenderOptions options;
    options.color_source = vc.source;
    const RenderResult r = RenderMesh(*mesh, atlas.view(), view, options);
    EXPECT_EQ(r.covered_pixels, width * height);

    double squared_error = 0.0;
    std::vector<double> depth_errors;
    for (int j = 0; j < height; ++j) {
      for (int i = 0; i < width; ++i) {
        const Eigen::Vector3d ray_cam((i + 0.5 - view.cx) / view.fx, (j + 0.5 - view.cy) / view.fy,
                                      1.0);
        const Eigen::Vector3d d = view.rotation.transpose() * ray_cam;
        double u, v;
        DirectionToEquirectPixel({d.x(), d.y(), d.z()}, w, h, &u, &v);
        // Colour: bilinear between the four surrounding front nodes (texture
        // edges that cross a quad cost a little, depth edges more).
        const double fx = u - 0.5, fy = std::clamp(v - 0.5, 0.0, h - 1.0);
        const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
        const double ax = fx - x0, ay = fy - y0;
        const int y1 = std::min(y0 + 1, h - 1);
        const size_t p00 = pano.index(WrapColumn(x0, w), y0),
                     p10 = pano.index(WrapColumn(x0 + 1, w), y0);
        const size_t p01 = pano.index(WrapColumn(x0, w), y1),
                     p11 = pano.index(WrapColumn(x0 + 1, w), y1);
        for (int c = 0; c < 3; ++c) {
          const double top =
              front.rgb[3 * p00 + c] + ax * (front.rgb[3 * p10 + c] - front.rgb[3 * p00 + c]);
          const double bottom =
              front.rgb[3 * p01 + c] + ax * (front.rgb[3 * p11 + c] - front.rgb[3 * p01 + c]);
          const double e = r.color.at(i, j, c) - (top + ay * (bottom - top));
          squared_error += e * e;
        }
        // Depth: the analytic scene (testing::MakeRoomPanorama's box room and
        // sphere) along the ray, as camera-frame z.
        const double want_z = AnalyticRoomDistance(d.normalized()) / ray_cam.norm();
        depth_errors.push_back(std::abs(r.depth.at(i, j) - want_z) / want_z);
      }
    }
    const double mse = squared_error / (3.0 * width * height);
    const double psnr = 10.0 * std::log10(255.0 * 255.0 / std::max(mse, 1e-12));
    EXPECT_GT(psnr, vc.min_psnr_db);
    std::printf("yaw %.0f pitch %.0f %s: %.2f dB\n", vc.yaw, vc.pitch,
                vc.source == ColorSource::kAtlas ? "atlas" : "vertex colours", psnr);
    std::sort(depth_errors.begin(), depth_errors.end());
    // Walls are planar between nodes, so depth is exact up to float rounding
    // (measured median 0, 95th percentile 1e-6) except at room corners and
    // along the sphere's polygonal silhouette (95th percentile 4e-4 there).
    EXPECT_LT(depth_errors[depth_errors.size() / 2], 1e-5);
    EXPECT_LT(depth_errors[depth_errors.size() * 95 / 100], 1e-3);
  }
}

// A foreground square at 1 m over a background at 3 m, with back nodes behind
// the square; every node's colour is the same affine function of its pixel,
// so bilinear atlas sampling and per-vertex interpolation agree exactly
// wherever each triangle samples the atlas at its own nodes' colours.
TwoLayerPanorama SquareOverBackground(int w, int h) {
  TwoLayerPanorama p(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = p.index(x, y);
      const bool square = x >= w / 2 - w / 16 && x < w / 2 + w / 16 && y >= h / 2 - h / 8 &&
                          y < h / 2 + h / 8;
      auto set = [&](int l, float depth_m) {
        LayerData& d = p.layer(l);
        d.present[i] = 1;
        d.depth_m[i] = depth_m;
        d.normal[3 * i + 2] = 1.0f;
        d.label[i] = static_cast<uint8_t>(l);
        d.rgb[3 * i] = static_cast<uint8_t>(20 + x);
        d.rgb[3 * i + 1] = static_cast<uint8_t>(10 + 3 * y);
        d.rgb[3 * i + 2] = static_cast<uint8_t>(230 - x);
      };
      set(kFront, square ? 1.0f : 3.0f);
      if (square) set(kBack, 3.0f);
    }
  }
  testing::LinkByDepthRatio(&p, 0.75f);
  return p;
}

double Psnr(const Image8& a, const Image8& b) {
  double squared_error = 0.0;
  for (size_t k = 0; k < a.size(); ++k) {
    const double e = static_cast<double>(a.data()[k]) - b.data()[k];
    squared_error += e * e;
  }
  const double mse = squared_error / static_cast<double>(a.size());
  return 10.0 * std::log10(255.0 * 255.0 / std::max(mse, 1e-12));
}

// Regression: triangles joining a front node and a back node used to have uvs
// in both halves of the atlas, so sampling across them read every atlas row in
// between and drew lines along each depth edge (measured 25.4 and 26.5 dB
// against vertex colours). Now each triangle samples one half, and the
// atlas's fill rule gives each vertex its node's colour there: the two
// renderings are identical (measured 168 dB, the floor of Psnr).
TEST(MeshRendererPanoramaTest, CrossLayerTrianglesSampleOneAtlasHalf) {
  const TwoLayerPanorama pano = SquareOverBackground(128, 64);
  const StatusOr<Mesh> mesh = BuildMesh(pano);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  const Image8 atlas = BuildColorAtlas(pano);
  // From the centre the cross-layer triangles show as a strip along the
  // square's outline; from 0.4 m to the side as the disocclusion beside it.
  const double eye_x[] = {0.0, 0.4};
  for (double x : eye_x) {
    SCOPED_TRACE("eye x " + std::to_string(x));
    GlCamera camera;
    camera.position[0] = x;
    camera.fov_y_deg = 50.0;
    const PinholeView view = ViewFromGlCamera(camera, 240, 180);
    RenderOptions options;
    const RenderResult with_atlas = RenderMesh(*mesh, atlas.view(), view, options);
    options.color_source = ColorSource::kVertexColors;
    const RenderResult with_colors = RenderMesh(*mesh, atlas.view(), view, options);
    EXPECT_EQ(with_atlas.covered_pixels, 240 * 180);
    EXPECT_EQ(with_atlas.mask, with_colors.mask);
    const double psnr = Psnr(with_atlas.color, with_colors.color);
    std::printf("eye x %.1f: atlas against vertex colours %.2f dB\n", x, psnr);
    EXPECT_GT(psnr, 45.0);
  }
}

}  // namespace
}  // namespace casual3d::render
