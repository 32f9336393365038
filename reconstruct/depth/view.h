#pragma once

// The dense stage's view of one photo: an undistorted pinhole camera, its pose
// and the images sampled at the stage's working resolution. Conversions from
// the COLMAP model (geometry::Camera, geometry::Pose) happen in one place,
// workspace.cc, so that the algorithms only see these plain types.
//
// Pixel convention (COLMAP's): the centre of pixel (x, y) is at continuous
// coordinates (x + 0.5, y + 0.5). Camera frame: +X right, +Y down, +Z forward.
// Depth means Z in the camera frame (metres along the optical axis).

#include <string>

#include <Eigen/Core>

#include "format/image.h"

namespace casual3d::depth {

struct PinholeCamera {
  int width = 0;   // Pixels.
  int height = 0;  // Pixels.
  double fx = 0, fy = 0, cx = 0, cy = 0;  // Pixels, COLMAP convention.
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // World to camera rotation.
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // World to camera translation.

  // The same camera resampled to width x height pixels (continuous
  // coordinates scale by width/old_width and height/old_height).
  PinholeCamera Resized(int new_width, int new_height) const {
    PinholeCamera c = *this;
    const double sx = static_cast<double>(new_width) / width;
    const double sy = static_cast<double>(new_height) / height;
    c.width = new_width;
    c.height = new_height;
    c.fx *= sx;
    c.cx *= sx;
    c.fy *= sy;
    c.cy *= sy;
    return c;
  }
  Eigen::Matrix3d K() const {
    Eigen::Matrix3d k;
    k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
    return k;
  }
  Eigen::Matrix3d KInverse() const {
    Eigen::Matrix3d k;
    k << 1 / fx, 0, -cx / fx, 0, 1 / fy, -cy / fy, 0, 0, 1;
    return k;
  }
  Eigen::Vector3d Center() const { return -R.transpose() * t; }
  // World point of pixel centre (x, y) (integer indices) at depth `depth_m`.
  Eigen::Vector3d Unproject(double x, double y, double depth_m) const {
    const Eigen::Vector3d cam(((x + 0.5) - cx) / fx * depth_m, ((y + 0.5) - cy) / fy * depth_m,
                              depth_m);
    return R.transpose() * (cam - t);
  }
};

// Per-photo inverse-depth sampling range of the plane sweep (metres).
struct DepthRange {
  double near_m = 0.0;
  double far_m = 0.0;
};

// One photo prepared for the dense stage.
struct DenseView {
  std::string name;       // Image name from the model (relative path).
  PinholeCamera camera;   // At working resolution.
  DepthRange range;
  ImageF gray;            // Working resolution, 1 channel, linear in [0, 1].
  ImageF color;           // Working resolution, 3 channels (RGB) in [0, 1].
  PinholeCamera camera_full;  // At the photo's full resolution.
  ImageF gray_full;       // Full resolution, 1 channel, in [0, 1] (the refinement's input).
  int full_width = 0;     // Size of the photo as stored in the workspace.
  int full_height = 0;
};

}  // namespace casual3d::depth
