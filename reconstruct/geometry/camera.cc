#include "reconstruct/geometry/camera.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace casual3d::geometry {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// Index layout of each model's parameter vector (COLMAP's order).
struct ModelLayout {
  CameraModelId id;
  const char* name;
  int num_params;
  int fx, fy, cx, cy;  // fy == fx for single-focal models.
  int first_extra;     // First distortion coefficient, num_params if none.
};

constexpr ModelLayout kLayouts[] = {
    {CameraModelId::kSimplePinhole, "SIMPLE_PINHOLE", 3, 0, 0, 1, 2, 3},
    {CameraModelId::kPinhole, "PINHOLE", 4, 0, 1, 2, 3, 4},
    {CameraModelId::kSimpleRadial, "SIMPLE_RADIAL", 4, 0, 0, 1, 2, 3},
    {CameraModelId::kRadial, "RADIAL", 5, 0, 0, 1, 2, 3},
    {CameraModelId::kOpenCV, "OPENCV", 8, 0, 1, 2, 3, 4},
};

const ModelLayout* FindLayout(CameraModelId id) {
  for (const ModelLayout& layout : kLayouts) {
    if (layout.id == id) return &layout;
  }
  return nullptr;
}

const ModelLayout& LayoutOrDie(CameraModelId id) {
  const ModelLayout* layout = FindLayout(id);
  if (layout == nullptr) {
    throw std::invalid_argument("camera model id " + std::to_string(static_cast<int>(id)) +
                                " is not supported");
  }
  return *layout;
}

// Distortion displacement and its Jacobian d(distorted)/d(undistorted) at
// normalized coordinates (u, v), following COLMAP's models.h formulas:
//   SIMPLE_RADIAL: radial = k r^2
//   RADIAL:        radial = k1 r^2 + k2 r^4
//   OPENCV:        radial as RADIAL, plus tangential
//                  du += 2 p1 u v + p2 (r^2 + 2 u^2), dv += 2 p2 u v + p1 (r^2 + 2 v^2)
// distorted = (u, v) + (u radial, v radial) + tangential.
void DistortWithJacobian(CameraModelId model, const double* extra, double u, double v,
                         double* du_out, double* dv_out, double jac[4]) {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;
  switch (model) {
    case CameraModelId::kSimpleRadial:
      k1 = extra[0];
      break;
    case CameraModelId::kRadial:
      k1 = extra[0];
      k2 = extra[1];
      break;
    case CameraModelId::kOpenCV:
      k1 = extra[0];
      k2 = extra[1];
      p1 = extra[2];
      p2 = extra[3];
      break;
    default:
      break;
  }
  const double u2 = u * u, v2 = v * v, uv = u * v;
  const double r2 = u2 + v2;
  const double radial = k1 * r2 + k2 * r2 * r2;
  *du_out = u * radial + 2.0 * p1 * uv + p2 * (r2 + 2.0 * u2);
  *dv_out = v * radial + 2.0 * p2 * uv + p1 * (r2 + 2.0 * v2);
  if (jac != nullptr) {
    // d(radial)/du = (2 k1 + 4 k2 r^2) u, likewise for v.
    const double dradial = 2.0 * k1 + 4.0 * k2 * r2;
    jac[0] = 1.0 + radial + u * dradial * u + 2.0 * p1 * v + p2 * 6.0 * u;  // d du' / du
    jac[1] = u * dradial * v + 2.0 * p1 * u + p2 * 2.0 * v;                 // d du' / dv
    jac[2] = v * dradial * u + 2.0 * p2 * v + p1 * 2.0 * u;                 // d dv' / du
    jac[3] = 1.0 + radial + v * dradial * v + 2.0 * p2 * u + p1 * 6.0 * v;  // d dv' / dv
  }
}

}  // namespace

const char* CameraModelName(CameraModelId id) {
  const ModelLayout* layout = FindLayout(id);
  return layout == nullptr ? nullptr : layout->name;
}

bool CameraModelFromName(const std::string& name, CameraModelId* id) {
  for (const ModelLayout& layout : kLayouts) {
    if (name == layout.name) {
      *id = layout.id;
      return true;
    }
  }
  return false;
}

bool CameraModelFromInt(int value, CameraModelId* id) {
  for (const ModelLayout& layout : kLayouts) {
    if (static_cast<int>(layout.id) == value) {
      *id = layout.id;
      return true;
    }
  }
  return false;
}

int CameraModelNumParams(CameraModelId id) {
  const ModelLayout* layout = FindLayout(id);
  return layout == nullptr ? 0 : layout->num_params;
}

double Camera::FocalX() const { return params.at(LayoutOrDie(model).fx); }
double Camera::FocalY() const { return params.at(LayoutOrDie(model).fy); }
double Camera::PrincipalX() const { return params.at(LayoutOrDie(model).cx); }
double Camera::PrincipalY() const { return params.at(LayoutOrDie(model).cy); }

bool Camera::HasDistortion() const {
  const ModelLayout& layout = LayoutOrDie(model);
  for (int i = layout.first_extra; i < layout.num_params && i < static_cast<int>(params.size());
       ++i) {
    if (params[i] != 0.0) return true;
  }
  return false;
}

Eigen::Vector2d Camera::Distort(const Eigen::Vector2d& normalized) const {
  const ModelLayout& layout = LayoutOrDie(model);
  if (layout.first_extra == layout.num_params) return normalized;
  double du, dv;
  DistortWithJacobian(model, params.data() + layout.first_extra, normalized.x(), normalized.y(),
                      &du, &dv, nullptr);
  return {normalized.x() + du, normalized.y() + dv};
}

Eigen::Vector2d Camera::Undistort(const Eigen::Vector2d& distorted) const {
  const ModelLayout& layout = LayoutOrDie(model);
  if (layout.first_extra == layout.num_params) return distorted;
  const double* extra = params.data() + layout.first_extra;
  // Newton's method on f(x) = x + d(x) - distorted, started at the distorted
  // point (COLMAP solves the same equation, with a numerical Jacobian).
  constexpr int kMaxIterations = 100;
  constexpr double kStepTolerance = 1e-14;
  double u = distorted.x(), v = distorted.y();
  for (int iter = 0; iter < kMaxIterations; ++iter) {
    double du, dv, j[4];
    DistortWithJacobian(model, extra, u, v, &du, &dv, j);
    const double ru = u + du - distorted.x();
    const double rv = v + dv - distorted.y();
    const double det = j[0] * j[3] - j[1] * j[2];
    if (std::abs(det) < 1e-300) break;
    const double step_u = (j[3] * ru - j[1] * rv) / det;
    const double step_v = (-j[2] * ru + j[0] * rv) / det;
    u -= step_u;
    v -= step_v;
    if (std::abs(step_u) + std::abs(step_v) < kStepTolerance * (1.0 + std::abs(u) + std::abs(v))) {
      break;
    }
  }
  return {u, v};
}

Eigen::Vector2d Camera::Project(const Eigen::Vector3d& point_cam) const {
  const Eigen::Vector2d normalized(point_cam.x() / point_cam.z(), point_cam.y() / point_cam.z());
  const Eigen::Vector2d d = Distort(normalized);
  return {FocalX() * d.x() + PrincipalX(), FocalY() * d.y() + PrincipalY()};
}

Eigen::Vector3d Camera::Unproject(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d distorted((pixel.x() - PrincipalX()) / FocalX(),
                                  (pixel.y() - PrincipalY()) / FocalY());
  const Eigen::Vector2d n = Undistort(distorted);
  return {n.x(), n.y(), 1.0};
}

double Camera::FovXDeg() const {
  // Sum of the angles either side of the principal point, so that an
  // off-centre principal point is measured correctly.
  const double fx = FocalX(), cx = PrincipalX();
  return (std::atan(cx / fx) + std::atan((width - cx) / fx)) * kRadToDeg;
}

double Camera::FovYDeg() const {
  const double fy = FocalY(), cy = PrincipalY();
  return (std::atan(cy / fy) + std::atan((height - cy) / fy)) * kRadToDeg;
}

Camera Camera::PinholePart() const {
  Camera pinhole;
  pinhole.camera_id = camera_id;
  pinhole.model = CameraModelId::kPinhole;
  pinhole.width = width;
  pinhole.height = height;
  pinhole.params = {FocalX(), FocalY(), PrincipalX(), PrincipalY()};
  return pinhole;
}

Camera Camera::Scaled(double scale) const {
  if (!(scale > 0.0) || width <= 0 || height <= 0) {
    throw std::invalid_argument("Camera::Scaled needs a positive scale and image size");
  }
  // With pixel centres at (i + 0.5), the image spans [0, width] x [0, height]
  // continuously, so resampling maps x -> x * sx exactly; sx and sy are the
  // ratios of the rounded sizes (as COLMAP's Camera::Rescale).
  const int new_width = std::max(1, static_cast<int>(std::lround(scale * width)));
  const int new_height = std::max(1, static_cast<int>(std::lround(scale * height)));
  const double sx = static_cast<double>(new_width) / width;
  const double sy = static_cast<double>(new_height) / height;
  const ModelLayout& layout = LayoutOrDie(model);
  Camera out = *this;
  out.width = new_width;
  out.height = new_height;
  if (layout.fx == layout.fy) {
    out.params[layout.fx] = params[layout.fx] * 0.5 * (sx + sy);
  } else {
    out.params[layout.fx] = params[layout.fx] * sx;
    out.params[layout.fy] = params[layout.fy] * sy;
  }
  out.params[layout.cx] = params[layout.cx] * sx;
  out.params[layout.cy] = params[layout.cy] * sy;
  return out;
}

bool Camera::IsValid(std::string* why) const {
  auto fail = [&](const std::string& reason) {
    if (why != nullptr) *why = reason;
    return false;
  };
  const ModelLayout* layout = FindLayout(model);
  if (layout == nullptr) {
    return fail("unsupported camera model id " + std::to_string(static_cast<int>(model)));
  }
  if (static_cast<int>(params.size()) != layout->num_params) {
    return fail(std::string(layout->name) + " needs " + std::to_string(layout->num_params) +
                " parameters, got " + std::to_string(params.size()));
  }
  if (width <= 0 || height <= 0) {
    return fail("image size " + std::to_string(width) + "x" + std::to_string(height) +
                " is not positive");
  }
  for (double p : params) {
    if (!std::isfinite(p)) return fail("a camera parameter is not finite");
  }
  if (!(FocalX() > 0.0) || !(FocalY() > 0.0)) return fail("focal length is not positive");
  return true;
}

}  // namespace casual3d::geometry
