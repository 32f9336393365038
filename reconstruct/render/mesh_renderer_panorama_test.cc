// The renderer on real 3D photo meshes (format/mesh_builder.h): seen from the
// panorama centre, the mesh must show the front layer's colour and depth in
// every direction, which ties the renderer, the mesh builder's uv and
// position conventions and format/equirect.h together.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "format/equirect.h"
#include "format/mesh_builder.h"
#include "format/testing/test_panoramas.h"
#include "reconstruct/render/mesh_renderer.h"

namespace casual3d::render {
namespace {

// The colour atlas of format/mesh.h: front colours above back colours.
Image8 MakeAtlas(const TwoLayerPanorama& pano) {
  const int w = pano.width(), h = pano.height();
  Image8 atlas(w, 2 * h, 3);
  for (int l = 0; l < kNumLayers; ++l) {
    const std::vector<uint8_t>& rgb = pano.layer(l).rgb;
    std::copy(rgb.begin(), rgb.end(), atlas.data() + static_cast<size_t>(l) * w * h * 3);
  }
  return atlas;
}

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
  const Image8 atlas = MakeAtlas(pano);
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
  // sphere has depth edges where the back layer shows (measured 34.3 dB); it
  // uses vertex colours because the triangles joining front and back nodes
  // have uvs in both halves of the atlas, and sampling between them reads the
  // rows in between (measured 27.9 dB with the atlas).
  const ViewCase cases[] = {{10, -10, ColorSource::kVertexColors, 32.0},
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
    std::sort(depth_errors.begin(), depth_errors.end());
    // Walls are planar between nodes, so depth is exact up to float rounding
    // (measured median 0, 95th percentile 1e-6) except at room corners and
    // along the sphere's polygonal silhouette (95th percentile 4e-4 there).
    EXPECT_LT(depth_errors[depth_errors.size() / 2], 1e-5);
    EXPECT_LT(depth_errors[depth_errors.size() * 95 / 100], 1e-3);
  }
}

}  // namespace
}  // namespace casual3d::render
