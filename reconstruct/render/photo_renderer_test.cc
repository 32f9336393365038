#include "reconstruct/render/photo_renderer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

namespace casual3d::render {
namespace {

// R = 2 x + 40, G = 3 y + 10, B = 77: linear in the texel, so bilinear
// filtering reproduces it exactly away from the borders.
Image8 LinearAtlas() {
  Image8 atlas(64, 64, 3);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      atlas.at(x, y, 0) = static_cast<uint8_t>(2 * x + 40);
      atlas.at(x, y, 1) = static_cast<uint8_t>(3 * y + 10);
      atlas.at(x, y, 2) = 77;
    }
  }
  return atlas;
}

// A 3 m x 2 m wall 2 m in front of the panorama centre (uv 0.25 ... 0.75).
Mesh Wall() {
  Mesh mesh;
  const float corners[4][5] = {{-1.5f, 1.f, -2.f, 0.25f, 0.25f},
                               {1.5f, 1.f, -2.f, 0.75f, 0.25f},
                               {1.5f, -1.f, -2.f, 0.75f, 0.75f},
                               {-1.5f, -1.f, -2.f, 0.25f, 0.75f}};
  for (const auto& c : corners) {
    mesh.positions.insert(mesh.positions.end(), {c[0], c[1], c[2]});
    mesh.normals.insert(mesh.normals.end(), {0.f, 0.f, 1.f});
    mesh.uvs.insert(mesh.uvs.end(), {c[3], c[4]});
    mesh.colors.insert(mesh.colors.end(), {0, 0, 0});
  }
  mesh.indices = {0, 1, 2, 0, 2, 3};
  return mesh;
}

// A photo's world rotated and shifted against the panorama frame, and a
// camera at the panorama centre looking forward, upright.
struct PhotoSetup {
  PanoramaFrame frame;
  geometry::Pose pose;
};

PhotoSetup MakeSetup() {
  PhotoSetup s;
  const Eigen::Matrix3d F =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, 1, -0.2).normalized()).toRotationMatrix();
  const Eigen::Vector3d centre(2.0, -0.5, 1.0);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) s.frame.rotation[3 * r + c] = F(r, c);
    s.frame.centre[r] = centre[r];
  }
  // x_cam = diag(1, -1, -1) p_panorama = diag(1, -1, -1) F (w - centre).
  const Eigen::Matrix3d R = Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix() * F;
  s.pose = geometry::Pose::FromCenter(R, centre);
  return s;
}

geometry::Camera MakeCamera(geometry::CameraModelId model, std::vector<double> params) {
  geometry::Camera camera;
  camera.camera_id = 3;
  camera.model = model;
  camera.width = 200;
  camera.height = 150;
  camera.params = std::move(params);
  return camera;
}

TEST(PhotoRendererTest, WithoutDistortionEqualsThePinholeRendering) {
  const PhotoSetup s = MakeSetup();
  const Image8 atlas = LinearAtlas();
  const geometry::Camera camera =
      MakeCamera(geometry::CameraModelId::kPinhole, {100.0, 101.0, 99.0, 76.0});
  const RenderResult a = RenderPhotoView(Wall(), atlas.view(), s.frame, camera, s.pose);
  const RenderResult b = RenderMesh(Wall(), atlas.view(), ViewFromPhoto(camera, s.pose, s.frame));
  EXPECT_TRUE(a.color == b.color);
  EXPECT_TRUE(a.depth == b.depth);
  EXPECT_GT(a.covered_pixels, 10000);
}

// Every pixel against the analytic answer: the pixel's distorted ray (through
// Camera::Unproject) meets the wall at z = -2 (panorama frame).
TEST(PhotoRendererTest, DistortedCamerasMatchRayCasting) {
  const PhotoSetup s = MakeSetup();
  const Image8 atlas = LinearAtlas();
  const geometry::Camera cameras[] = {
      MakeCamera(geometry::CameraModelId::kSimpleRadial, {100.0, 100.0, 75.0, 0.05}),
      MakeCamera(geometry::CameraModelId::kRadial, {100.0, 101.0, 74.0, -0.05, 0.004}),
      MakeCamera(geometry::CameraModelId::kOpenCV,
                 {100.0, 98.0, 100.5, 75.5, -0.04, 0.003, 0.002, -0.003}),
  };
  for (const geometry::Camera& camera : cameras) {
    SCOPED_TRACE(geometry::CameraModelName(camera.model));
    const RenderResult r = RenderPhotoView(Wall(), atlas.view(), s.frame, camera, s.pose);
    const RenderResult pinhole =
        RenderMesh(Wall(), atlas.view(), ViewFromPhoto(camera, s.pose, s.frame));
    int mismatched = 0, checked = 0, differs_from_pinhole = 0;
    double max_color_error = 0.0;
    for (int j = 0; j < camera.height; ++j) {
      for (int i = 0; i < camera.width; ++i) {
        const Eigen::Vector3d ray = camera.Unproject(Eigen::Vector2d(i + 0.5, j + 0.5));
        // Camera = diag(1, -1, -1) panorama: the ray in the panorama frame.
        const Eigen::Vector3d d(ray.x(), -ray.y(), -1.0);
        const double lambda = 2.0;  // Meets z = -2 at parameter 2; depth is 2.
        const double x = lambda * d.x(), y = lambda * d.y();
        // Coverage comes from the nearest canvas pixel, so it may go either
        // way within 0.75 pixel (0.015 m at 2 m with f = 100) of the border.
        const double band = 0.015;
        const bool inside = std::abs(x) < 1.5 - band && std::abs(y) < 1.0 - band;
        const bool outside = std::abs(x) > 1.5 + band || std::abs(y) > 1.0 + band;
        const bool got = r.mask.at(i, j) == 255;
        if (got != (pinhole.mask.at(i, j) == 255) ||
            (got && std::abs(r.color.at(i, j, 0) - pinhole.color.at(i, j, 0)) +
                            std::abs(r.color.at(i, j, 1) - pinhole.color.at(i, j, 1)) >
                        2)) {
          ++differs_from_pinhole;
        }
        if ((inside && !got) || (outside && got)) ++mismatched;
        if (!inside || !got) continue;
        ++checked;
        EXPECT_NEAR(r.depth.at(i, j), 2.0, 1e-5);
        const double u = 0.25 + 0.5 * (x + 1.5) / 3.0, v = 0.25 + 0.5 * (1.0 - y) / 2.0;
        const double want_r = 2.0 * (u * 64 - 0.5) + 40, want_g = 3.0 * (v * 64 - 0.5) + 10;
        max_color_error = std::max(max_color_error, std::abs(r.color.at(i, j, 0) - want_r));
        max_color_error = std::max(max_color_error, std::abs(r.color.at(i, j, 1) - want_g));
      }
    }
    EXPECT_GT(checked, 12000);
    EXPECT_EQ(mismatched, 0);
    EXPECT_LE(max_color_error, 1.25);  // Measured 0.97.
    // The distortion is strong enough to matter: the pinhole rendering
    // differs in coverage or colour on 640 to 972 pixels (measured).
    EXPECT_GT(differs_from_pinhole, 400);
  }
}

TEST(PhotoRendererTest, RejectsInvalidCamera) {
  const PhotoSetup s = MakeSetup();
  const Image8 atlas = LinearAtlas();
  geometry::Camera camera = MakeCamera(geometry::CameraModelId::kSimpleRadial, {100.0, 100.0});
  try {
    RenderPhotoView(Wall(), atlas.view(), s.frame, camera, s.pose);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "camera 3: SIMPLE_RADIAL needs 4 parameters, got 2");
  }
}

}  // namespace
}  // namespace casual3d::render
