#pragma once

// Rigid poses in COLMAP's convention: a world-to-camera rotation (unit
// quaternion, w first in files) and translation, x_cam = R * x_world + t.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace casual3d::geometry {

struct Pose {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // World to camera.
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();         // World to camera.

  Eigen::Matrix3d R() const { return rotation.toRotationMatrix(); }
  Eigen::Matrix<double, 3, 4> Matrix3x4() const;  // [R | t].
  Eigen::Vector3d WorldToCamera(const Eigen::Vector3d& x_world) const;
  Eigen::Vector3d CameraToWorld(const Eigen::Vector3d& x_cam) const;
  // Camera centre in world coordinates: -R^T t.
  Eigen::Vector3d Center() const;
  // Optical axis (camera +Z) in world coordinates.
  Eigen::Vector3d ViewingDirection() const;
  // The camera's up (camera -Y, since image rows grow downwards) in world coordinates.
  Eigen::Vector3d UpVector() const;
  Pose Inverse() const;  // Camera-to-world as a Pose.

  // From a camera centre and world-to-camera rotation.
  static Pose FromCenter(const Eigen::Matrix3d& R_world_to_cam, const Eigen::Vector3d& center);
  // A camera at `center` looking at `target`, with image up as close to `up` as possible.
  static Pose LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
                     const Eigen::Vector3d& up);
};

// Angle between two rotations, degrees.
double RotationAngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

// A similarity transform y = scale * R * x + t.
struct Similarity3 {
  double scale = 1.0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3d Apply(const Eigen::Vector3d& x) const { return scale * (R * x) + t; }
  // Transforms a world-to-camera pose of the source world into the target world.
  Pose ApplyToPose(const Pose& pose) const;
};

// Least-squares similarity (Umeyama 1991) mapping src[i] to dst[i]; needs >= 3
// non-collinear points. Returns false if degenerate.
bool EstimateSimilarity(const std::vector<Eigen::Vector3d>& src,
                        const std::vector<Eigen::Vector3d>& dst, Similarity3* sim);

}  // namespace casual3d::geometry
