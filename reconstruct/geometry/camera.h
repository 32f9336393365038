#pragma once

// Camera models as COLMAP defines them (src/colmap/sensor/models.h): the same
// names, ids, parameter order and pixel convention, so that models read from a
// COLMAP workspace mean the same thing here.
//
// Pixel convention (COLMAP's): the centre of the top-left pixel is (0.5, 0.5).
// Camera frame: +X right, +Y down, +Z forward (the optical axis).
// "Normalized" image coordinates are (X/Z, Y/Z) before distortion.

#include <string>
#include <vector>

#include <Eigen/Core>

namespace casual3d::geometry {

enum class CameraModelId : int {
  kSimplePinhole = 0,  // f, cx, cy
  kPinhole = 1,        // fx, fy, cx, cy
  kSimpleRadial = 2,   // f, cx, cy, k
  kRadial = 3,         // f, cx, cy, k1, k2
  kOpenCV = 4,         // fx, fy, cx, cy, k1, k2, p1, p2
};

// "SIMPLE_PINHOLE", ...; nullptr for an unknown id.
const char* CameraModelName(CameraModelId id);
// Parses a COLMAP model name; false if unknown or unsupported.
bool CameraModelFromName(const std::string& name, CameraModelId* id);
// Parses a COLMAP numeric model id; false if unknown or unsupported.
bool CameraModelFromInt(int value, CameraModelId* id);
// Number of parameters of the model.
int CameraModelNumParams(CameraModelId id);

struct Camera {
  int camera_id = 0;
  CameraModelId model = CameraModelId::kPinhole;
  int width = 0;   // Pixels.
  int height = 0;  // Pixels.
  std::vector<double> params;  // In COLMAP's order for `model`.

  double FocalX() const;
  double FocalY() const;
  double PrincipalX() const;
  double PrincipalY() const;
  bool HasDistortion() const;  // Any non-zero distortion coefficient.

  // Camera-frame point (Z > 0) to pixel, with distortion.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_cam) const;
  // Pixel to a ray direction in the camera frame with Z = 1 (undistorts).
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const;
  // Normalized undistorted coordinates -> normalized distorted coordinates.
  Eigen::Vector2d Distort(const Eigen::Vector2d& normalized) const;
  // Inverse of Distort (iterative; accurate to about 1e-10 in normalized units
  // inside the image's field of view).
  Eigen::Vector2d Undistort(const Eigen::Vector2d& distorted) const;

  // Horizontal and vertical field of view of the undistorted pinhole model.
  double FovXDeg() const;
  double FovYDeg() const;

  // A PINHOLE camera with the same size, focal lengths and principal point.
  Camera PinholePart() const;
  // The camera for the same sensor resampled by `scale` (new = old * scale):
  // size rounded, focal lengths and principal point scaled consistently with
  // the (0.5, 0.5) pixel-centre convention.
  Camera Scaled(double scale) const;

  // Checks the parameter count and that focal lengths and size are positive.
  bool IsValid(std::string* why = nullptr) const;
};

}  // namespace casual3d::geometry
