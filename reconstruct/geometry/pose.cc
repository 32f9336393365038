#include "reconstruct/geometry/pose.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace casual3d::geometry {

Eigen::Matrix<double, 3, 4> Pose::Matrix3x4() const {
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = R();
  m.col(3) = translation;
  return m;
}

Eigen::Vector3d Pose::WorldToCamera(const Eigen::Vector3d& x_world) const {
  return rotation * x_world + translation;
}

Eigen::Vector3d Pose::CameraToWorld(const Eigen::Vector3d& x_cam) const {
  return rotation.conjugate() * (x_cam - translation);
}

Eigen::Vector3d Pose::Center() const { return -(rotation.conjugate() * translation); }

Eigen::Vector3d Pose::ViewingDirection() const {
  return rotation.conjugate() * Eigen::Vector3d::UnitZ();
}

Eigen::Vector3d Pose::UpVector() const {
  return rotation.conjugate() * Eigen::Vector3d(0.0, -1.0, 0.0);
}

Pose Pose::Inverse() const {
  Pose inverse;
  inverse.rotation = rotation.conjugate();
  inverse.translation = -(inverse.rotation * translation);
  return inverse;
}

Pose Pose::FromCenter(const Eigen::Matrix3d& R_world_to_cam, const Eigen::Vector3d& center) {
  Pose pose;
  pose.rotation = Eigen::Quaterniond(R_world_to_cam).normalized();
  pose.translation = -(pose.rotation * center);
  return pose;
}

Pose Pose::LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
                  const Eigen::Vector3d& up) {
  // Rows of the world-to-camera rotation are the camera axes in world
  // coordinates: x right, y down, z forward (right-handed: y = z cross x).
  const Eigen::Vector3d z = (target - center).normalized();
  Eigen::Vector3d x = z.cross(up);
  if (x.squaredNorm() < 1e-24) {
    // `up` is parallel to the viewing direction: pick any perpendicular axis.
    const Eigen::Vector3d helper =
        std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    x = z.cross(helper);
  }
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  return FromCenter(R, center);
}

double RotationAngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  // |w| of the relative rotation gives cos(angle / 2); the absolute value
  // makes q and -q equal.
  const Eigen::Quaterniond rel = a.normalized().conjugate() * b.normalized();
  const double w = std::min(1.0, std::abs(rel.w()));
  const double vec = rel.vec().norm();
  return 2.0 * std::atan2(vec, w) * 180.0 / 3.14159265358979323846;
}

Pose Similarity3::ApplyToPose(const Pose& pose) const {
  // Centre moves as a point; the new world-to-camera rotation is R_cam * R^T.
  const Eigen::Matrix3d R_new = pose.R() * R.transpose();
  return Pose::FromCenter(R_new, Apply(pose.Center()));
}

bool EstimateSimilarity(const std::vector<Eigen::Vector3d>& src,
                        const std::vector<Eigen::Vector3d>& dst, Similarity3* sim) {
  const size_t n = src.size();
  if (n < 3 || dst.size() != n) return false;
  // Umeyama (1991): centre both sets, SVD of the cross-covariance, reflection
  // correction, then scale from the source variance.
  Eigen::Vector3d mean_src = Eigen::Vector3d::Zero(), mean_dst = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    mean_src += src[i];
    mean_dst += dst[i];
  }
  mean_src /= static_cast<double>(n);
  mean_dst /= static_cast<double>(n);

  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  double var_src = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = src[i] - mean_src;
    const Eigen::Vector3d b = dst[i] - mean_dst;
    cov += b * a.transpose();
    var_src += a.squaredNorm();
  }
  cov /= static_cast<double>(n);
  var_src /= static_cast<double>(n);
  if (!(var_src > 0.0) || !std::isfinite(var_src)) return false;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d sv = svd.singularValues();
  // Collinear (or coincident) points leave the rotation about their line
  // undetermined: the second singular value vanishes.
  if (!(sv(1) > 1e-12 * sv(0)) || !(sv(0) > 0.0)) return false;

  Eigen::Vector3d s = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s(2) = -1.0;
  sim->R = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
  sim->scale = sv.dot(s) / var_src;
  sim->t = mean_dst - sim->scale * (sim->R * mean_src);
  return std::isfinite(sim->scale) && sim->scale > 0.0;
}

}  // namespace casual3d::geometry
