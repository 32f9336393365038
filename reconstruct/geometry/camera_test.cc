#include "reconstruct/geometry/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace casual3d::geometry {
namespace {

Camera MakeCamera(CameraModelId model, std::vector<double> params, int width = 4032,
                  int height = 3024) {
  Camera camera;
  camera.camera_id = 1;
  camera.model = model;
  camera.width = width;
  camera.height = height;
  camera.params = std::move(params);
  return camera;
}

// Realistic cameras: a phone main camera (about 65 x 50 degrees) and a
// wide-angle lens with stronger barrel distortion and slight decentering.
std::vector<Camera> TestCameras() {
  return {
      MakeCamera(CameraModelId::kSimplePinhole, {3200.0, 2016.0, 1512.0}),
      MakeCamera(CameraModelId::kPinhole, {3210.0, 3190.0, 2010.5, 1520.25}),
      MakeCamera(CameraModelId::kSimpleRadial, {3260.0, 2016.0, 1512.0, 0.0213}),
      MakeCamera(CameraModelId::kSimpleRadial, {2200.0, 2016.0, 1512.0, -0.08}),
      MakeCamera(CameraModelId::kRadial, {3260.0, 2016.0, 1512.0, -0.034, 0.0125}),
      MakeCamera(CameraModelId::kRadial, {1600.0, 2000.0, 1500.0, -0.12, 0.02}),
      MakeCamera(CameraModelId::kOpenCV,
                 {3255.0, 3248.0, 2021.0, 1507.0, -0.041, 0.018, 0.0011, -0.0007}),
      MakeCamera(CameraModelId::kOpenCV,
                 {1700.0, 1690.0, 2030.0, 1495.0, -0.15, 0.03, 0.002, -0.0015}),
  };
}

TEST(CameraModelTest, NamesIdsAndParamCounts) {
  struct Expected {
    CameraModelId id;
    const char* name;
    int value;
    int num_params;
  };
  const Expected expected[] = {{CameraModelId::kSimplePinhole, "SIMPLE_PINHOLE", 0, 3},
                               {CameraModelId::kPinhole, "PINHOLE", 1, 4},
                               {CameraModelId::kSimpleRadial, "SIMPLE_RADIAL", 2, 4},
                               {CameraModelId::kRadial, "RADIAL", 3, 5},
                               {CameraModelId::kOpenCV, "OPENCV", 4, 8}};
  for (const Expected& e : expected) {
    EXPECT_STREQ(CameraModelName(e.id), e.name);
    EXPECT_EQ(CameraModelNumParams(e.id), e.num_params);
    CameraModelId id;
    ASSERT_TRUE(CameraModelFromName(e.name, &id));
    EXPECT_EQ(id, e.id);
    ASSERT_TRUE(CameraModelFromInt(e.value, &id));
    EXPECT_EQ(id, e.id);
  }
  CameraModelId id;
  EXPECT_FALSE(CameraModelFromName("FULL_OPENCV", &id));
  EXPECT_FALSE(CameraModelFromName("pinhole", &id));
  EXPECT_FALSE(CameraModelFromInt(6, &id));
  EXPECT_FALSE(CameraModelFromInt(-1, &id));
  EXPECT_EQ(CameraModelName(static_cast<CameraModelId>(42)), nullptr);
}

TEST(CameraModelTest, AccessorsFollowColmapParameterOrder) {
  const Camera opencv = MakeCamera(CameraModelId::kOpenCV, {10, 11, 12, 13, 0, 0, 0, 0});
  EXPECT_EQ(opencv.FocalX(), 10);
  EXPECT_EQ(opencv.FocalY(), 11);
  EXPECT_EQ(opencv.PrincipalX(), 12);
  EXPECT_EQ(opencv.PrincipalY(), 13);
  EXPECT_FALSE(opencv.HasDistortion());
  const Camera radial = MakeCamera(CameraModelId::kRadial, {20, 21, 22, 0, 0.1});
  EXPECT_EQ(radial.FocalX(), 20);
  EXPECT_EQ(radial.FocalY(), 20);
  EXPECT_EQ(radial.PrincipalX(), 21);
  EXPECT_EQ(radial.PrincipalY(), 22);
  EXPECT_TRUE(radial.HasDistortion());
}

// The distortion formulas written out independently of the implementation.
TEST(CameraModelTest, DistortMatchesColmapFormulas) {
  const double u = 0.31, v = -0.22;
  const double r2 = u * u + v * v;
  {
    const Camera c = MakeCamera(CameraModelId::kSimpleRadial, {1000, 500, 400, 0.05});
    const Eigen::Vector2d d = c.Distort({u, v});
    EXPECT_NEAR(d.x(), u * (1 + 0.05 * r2), 1e-15);
    EXPECT_NEAR(d.y(), v * (1 + 0.05 * r2), 1e-15);
  }
  {
    const Camera c = MakeCamera(CameraModelId::kRadial, {1000, 500, 400, -0.1, 0.03});
    const double radial = -0.1 * r2 + 0.03 * r2 * r2;
    const Eigen::Vector2d d = c.Distort({u, v});
    EXPECT_NEAR(d.x(), u * (1 + radial), 1e-15);
    EXPECT_NEAR(d.y(), v * (1 + radial), 1e-15);
  }
  {
    const double k1 = -0.1, k2 = 0.03, p1 = 0.002, p2 = -0.004;
    const Camera c = MakeCamera(CameraModelId::kOpenCV, {1000, 990, 500, 400, k1, k2, p1, p2});
    const double radial = k1 * r2 + k2 * r2 * r2;
    const Eigen::Vector2d d = c.Distort({u, v});
    EXPECT_NEAR(d.x(), u + u * radial + 2 * p1 * u * v + p2 * (r2 + 2 * u * u), 1e-15);
    EXPECT_NEAR(d.y(), v + v * radial + 2 * p2 * u * v + p1 * (r2 + 2 * v * v), 1e-15);
    // Project applies the focal lengths and principal point after distortion.
    const Eigen::Vector2d px = c.Project({u * 2.5, v * 2.5, 2.5});
    EXPECT_NEAR(px.x(), 1000 * d.x() + 500, 1e-10);
    EXPECT_NEAR(px.y(), 990 * d.y() + 400, 1e-10);
  }
}

// Every pixel centre on a dense grid covering the whole image, including the
// corners, unprojects and projects back to itself.
TEST(CameraModelTest, UnprojectProjectRoundTripOverWholeImage) {
  for (const Camera& camera : TestCameras()) {
    SCOPED_TRACE(std::string(CameraModelName(camera.model)) +
                 " f=" + std::to_string(camera.FocalX()));
    double max_error = 0.0;
    for (int j = 0; j <= 60; ++j) {
      for (int i = 0; i <= 80; ++i) {
        const Eigen::Vector2d pixel(camera.width * i / 80.0, camera.height * j / 60.0);
        const Eigen::Vector3d ray = camera.Unproject(pixel);
        EXPECT_DOUBLE_EQ(ray.z(), 1.0);
        // Any point on the ray projects to the same pixel.
        const Eigen::Vector2d back = camera.Project(ray * 3.7);
        max_error = std::max(max_error, (back - pixel).norm());
      }
    }
    EXPECT_LT(max_error, 1e-6);
  }
}

TEST(CameraModelTest, DistortUndistortRoundTripOverWholeImage) {
  for (const Camera& camera : TestCameras()) {
    SCOPED_TRACE(CameraModelName(camera.model));
    double max_error_px = 0.0;
    for (int j = 0; j <= 48; ++j) {
      for (int i = 0; i <= 64; ++i) {
        const Eigen::Vector2d pixel(camera.width * i / 64.0, camera.height * j / 48.0);
        const Eigen::Vector2d distorted((pixel.x() - camera.PrincipalX()) / camera.FocalX(),
                                        (pixel.y() - camera.PrincipalY()) / camera.FocalY());
        const Eigen::Vector2d undistorted = camera.Undistort(distorted);
        const Eigen::Vector2d redistorted = camera.Distort(undistorted);
        max_error_px = std::max(max_error_px, (redistorted - distorted).norm() * camera.FocalX());
        // And in the other direction, from undistorted coordinates.
        const Eigen::Vector2d again = camera.Undistort(camera.Distort(distorted));
        max_error_px = std::max(max_error_px, (again - distorted).norm() * camera.FocalX());
      }
    }
    EXPECT_LT(max_error_px, 1e-6);
  }
}

TEST(CameraModelTest, DistortionActuallyMovesPixels) {
  // Guards against a model silently ignoring its coefficients: near the
  // corner of a phone image, k = 0.0213 moves points by tens of pixels.
  const Camera c = MakeCamera(CameraModelId::kSimpleRadial, {3260.0, 2016.0, 1512.0, 0.0213});
  const Eigen::Vector2d corner_ray(2016.0 / 3260.0, 1512.0 / 3260.0);
  const Eigen::Vector2d shift = (c.Distort(corner_ray) - corner_ray) * 3260.0;
  const double r2 = corner_ray.squaredNorm();
  EXPECT_NEAR(shift.norm(), 0.0213 * r2 * corner_ray.norm() * 3260.0, 1e-9);
  EXPECT_GT(shift.norm(), 20.0);
}

TEST(CameraModelTest, FieldOfView) {
  // A 4032 x 3024 sensor with f = 3200 px: 2 atan(2016 / 3200) = 64.42 deg.
  const Camera c = MakeCamera(CameraModelId::kSimplePinhole, {3200.0, 2016.0, 1512.0});
  EXPECT_NEAR(c.FovXDeg(), 2.0 * std::atan(2016.0 / 3200.0) * 180.0 / M_PI, 1e-12);
  EXPECT_NEAR(c.FovXDeg(), 64.42, 0.01);
  EXPECT_NEAR(c.FovYDeg(), 50.58, 0.01);
  // An off-centre principal point: the two half-angles differ.
  const Camera off = MakeCamera(CameraModelId::kPinhole, {1000.0, 800.0, 300.0, 200.0}, 1000, 600);
  EXPECT_NEAR(off.FovXDeg(), (std::atan(0.3) + std::atan(0.7)) * 180.0 / M_PI, 1e-12);
  EXPECT_NEAR(off.FovYDeg(), (std::atan(0.25) + std::atan(0.5)) * 180.0 / M_PI, 1e-12);
}

TEST(CameraModelTest, PinholePartDropsDistortionOnly) {
  const Camera c = MakeCamera(CameraModelId::kOpenCV,
                              {3255.0, 3248.0, 2021.0, 1507.0, -0.041, 0.018, 0.0011, -0.0007});
  const Camera p = c.PinholePart();
  EXPECT_EQ(p.model, CameraModelId::kPinhole);
  EXPECT_EQ(p.width, c.width);
  EXPECT_EQ(p.height, c.height);
  EXPECT_EQ(p.params, (std::vector<double>{3255.0, 3248.0, 2021.0, 1507.0}));
  EXPECT_TRUE(p.IsValid());
}

TEST(CameraModelTest, ScaledKeepsImageEdgesAndRays) {
  const Camera c = MakeCamera(CameraModelId::kRadial, {3260.0, 2016.0, 1512.0, -0.034, 0.0125});
  const Camera s = c.Scaled(0.25);
  EXPECT_EQ(s.width, 1008);
  EXPECT_EQ(s.height, 756);
  EXPECT_DOUBLE_EQ(s.FocalX(), 815.0);
  EXPECT_DOUBLE_EQ(s.PrincipalX(), 504.0);
  EXPECT_DOUBLE_EQ(s.PrincipalY(), 378.0);
  EXPECT_EQ(s.params[3], c.params[3]);  // Distortion is in normalized units.
  // A 3D point projects to the same place relative to the image size.
  const Eigen::Vector3d point(0.4, -0.3, 1.7);
  const Eigen::Vector2d a = c.Project(point), b = s.Project(point);
  EXPECT_NEAR(b.x(), a.x() * 0.25, 1e-9);
  EXPECT_NEAR(b.y(), a.y() * 0.25, 1e-9);

  // Sizes that do not divide: each axis uses its own rounded ratio.
  const Camera p = MakeCamera(CameraModelId::kPinhole, {1000, 1000, 500.5, 300.5}, 1001, 601);
  const Camera q = p.Scaled(0.5);
  EXPECT_EQ(q.width, 501);   // round(500.5) away from zero
  EXPECT_EQ(q.height, 301);  // round(300.5)
  EXPECT_DOUBLE_EQ(q.FocalX(), 1000.0 * 501.0 / 1001.0);
  EXPECT_DOUBLE_EQ(q.FocalY(), 1000.0 * 301.0 / 601.0);
  // The image centre stays the image centre.
  EXPECT_NEAR(q.PrincipalX(), q.width / 2.0, 1e-9);
  EXPECT_NEAR(q.PrincipalY(), q.height / 2.0, 1e-9);
  EXPECT_THROW(p.Scaled(0.0), std::invalid_argument);
}

TEST(CameraModelTest, IsValidExplainsProblems) {
  std::string why;
  EXPECT_TRUE(MakeCamera(CameraModelId::kSimpleRadial, {1000, 500, 400, 0.01}).IsValid(&why));
  EXPECT_FALSE(MakeCamera(CameraModelId::kSimpleRadial, {1000, 500, 400}).IsValid(&why));
  EXPECT_EQ(why, "SIMPLE_RADIAL needs 4 parameters, got 3");
  EXPECT_FALSE(MakeCamera(CameraModelId::kPinhole, {1000, -5, 500, 400}).IsValid(&why));
  EXPECT_EQ(why, "focal length is not positive");
  EXPECT_FALSE(MakeCamera(CameraModelId::kPinhole, {1000, 1000, 500, 400}, 0, 10).IsValid(&why));
  EXPECT_EQ(why, "image size 0x10 is not positive");
  EXPECT_FALSE(MakeCamera(CameraModelId::kPinhole, {NAN, 1000, 500, 400}).IsValid(&why));
  EXPECT_EQ(why, "a camera parameter is not finite");
}

}  // namespace
}  // namespace casual3d::geometry
