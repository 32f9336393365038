#pragma once

// A small analytic scene for the panorama stages' tests: a textured plane at
// world z = -plane_z (panorama forward is -Z) with a nearer square
// |x|, |y| < half_size at z = -near_z, seen by pinhole cameras looking forward.

#include <cmath>

#include <Eigen/Core>

#include "format/equirect.h"
#include "format/image.h"
#include "reconstruct/geometry/camera.h"
#include "reconstruct/geometry/pose.h"

namespace casual3d::warp::testing {

inline geometry::Camera MakeCamera(int w, int h, double fov_x_deg) {
  geometry::Camera cam;
  cam.model = geometry::CameraModelId::kPinhole;
  cam.width = w;
  cam.height = h;
  const double f = 0.5 * w / std::tan(0.5 * fov_x_deg * kPi / 180.0);
  cam.params = {f, f, 0.5 * w, 0.5 * h};
  return cam;
}

// Camera x = +X, y = -Y (down), z = -Z (forward).
inline geometry::Pose ForwardPose(const Eigen::Vector3d& centre) {
  Eigen::Matrix3d R;
  R << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  return geometry::Pose::FromCenter(R, centre);
}

struct SquareScene {
  double plane_z = 4.0;
  double near_z = 1.0;
  double half_size = 0.3;
};

// Renders depth (metres along the optical axis) and colour: the square has
// red 250, the plane red 10; green and blue carry a texture of world x, y.
inline void RenderSquareScene(const SquareScene& scene, const geometry::Camera& cam,
                              const geometry::Pose& pose, ImageF* depth, Image8* rgb) {
  *depth = ImageF(cam.width, cam.height, 1, 0.0f);
  *rgb = Image8(cam.width, cam.height, 3, 0);
  const Eigen::Vector3d c = pose.Center();
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const Eigen::Vector3d ray_cam = cam.Unproject(Eigen::Vector2d(x + 0.5, y + 0.5));
      const Eigen::Vector3d ray = pose.R().transpose() * ray_cam;
      double t = (-scene.near_z - c.z()) / ray.z();
      Eigen::Vector3d p = c + t * ray;
      const bool is_near = std::abs(p.x()) < scene.half_size && std::abs(p.y()) < scene.half_size;
      if (!is_near) {
        t = (-scene.plane_z - c.z()) / ray.z();
        p = c + t * ray;
      }
      depth->at(x, y) = static_cast<float>(t * ray_cam.z());
      rgb->at(x, y, 0) = is_near ? 250 : 10;
      rgb->at(x, y, 1) = static_cast<uint8_t>(128 + 100 * std::sin(p.x() * 20));
      rgb->at(x, y, 2) = static_cast<uint8_t>(128 + 100 * std::sin(p.y() * 20));
    }
  }
}

// True distance from the origin to the scene along panorama direction `d`.
inline double SquareSceneRadialDepth(const SquareScene& scene, const Vec3d& d) {
  if (d.z >= 0) return 0;
  const double t_near = -scene.near_z / d.z;
  if (std::abs(t_near * d.x) < scene.half_size && std::abs(t_near * d.y) < scene.half_size) {
    return t_near;
  }
  return -scene.plane_z / d.z;
}

}  // namespace casual3d::warp::testing
