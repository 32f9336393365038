#include "reconstruct/synth/primitives.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace casual3d::synth {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool Finish(double t0, double t1, int face, Interval* out) {
  if (t1 < 0 || t0 > t1) return false;
  out->t_in = t0;
  out->t_out = t1;
  out->face_in = face;
  return true;
}

}  // namespace

bool IntersectPrimitive(const Primitive& prim, const Eigen::Vector3d& origin,
                        const Eigen::Vector3d& dir, Interval* interval) {
  // Work in the solid's local frame.
  const Eigen::Vector3d o = prim.axes.transpose() * (origin - prim.centre);
  const Eigen::Vector3d d = prim.axes.transpose() * dir;
  switch (prim.shape) {
    case Shape::kSphere: {
      const double r = prim.half.x();
      const double a = d.squaredNorm();
      const double b = o.dot(d);
      const double c = o.squaredNorm() - r * r;
      const double disc = b * b - a * c;
      if (disc < 0) return false;
      const double s = std::sqrt(disc);
      // Numerically stable roots.
      const double q = b >= 0 ? -(b + s) : -(b - s);
      double t0 = q / a, t1 = (q != 0) ? c / q : t0;
      if (t0 > t1) std::swap(t0, t1);
      return Finish(t0, t1, 0, interval);
    }
    case Shape::kBox: {
      double t0 = -kInf, t1 = kInf;
      int face = 0;
      for (int k = 0; k < 3; ++k) {
        if (std::abs(d[k]) < 1e-300) {
          if (std::abs(o[k]) > prim.half[k]) return false;
          continue;
        }
        const double inv = 1.0 / d[k];
        double ta = (-prim.half[k] - o[k]) * inv;
        double tb = (prim.half[k] - o[k]) * inv;
        // Entering through the -k face when moving in +k.
        int fa = 2 * k, fb = 2 * k + 1;
        if (ta > tb) {
          std::swap(ta, tb);
          std::swap(fa, fb);
        }
        if (ta > t0) {
          t0 = ta;
          face = fa;
        }
        t1 = std::min(t1, tb);
        if (t0 > t1) return false;
      }
      return Finish(t0, t1, face, interval);
    }
    case Shape::kCylinder: {
      const double r = prim.half.x(), h = prim.half.y();
      double t0 = -kInf, t1 = kInf;
      int face = 0;
      // Infinite cylinder x^2 + z^2 = r^2.
      const double a = d.x() * d.x() + d.z() * d.z();
      const double c = o.x() * o.x() + o.z() * o.z() - r * r;
      if (a < 1e-300) {
        if (c > 0) return false;
      } else {
        const double b = o.x() * d.x() + o.z() * d.z();
        const double disc = b * b - a * c;
        if (disc < 0) return false;
        const double s = std::sqrt(disc);
        const double q = b >= 0 ? -(b + s) : -(b - s);
        double ta = q / a, tb = (q != 0) ? c / q : ta;
        if (ta > tb) std::swap(ta, tb);
        t0 = ta;
        t1 = tb;
      }
      // Slab |y| <= h (caps).
      if (std::abs(d.y()) < 1e-300) {
        if (std::abs(o.y()) > h) return false;
      } else {
        const double inv = 1.0 / d.y();
        double ta = (-h - o.y()) * inv, tb = (h - o.y()) * inv;
        int fa = 1, fb = 2;
        if (ta > tb) {
          std::swap(ta, tb);
          std::swap(fa, fb);
        }
        if (ta > t0) {
          t0 = ta;
          face = fa;
        }
        t1 = std::min(t1, tb);
      }
      return Finish(t0, t1, face, interval);
    }
  }
  return false;
}

Eigen::Vector3d PrimitiveNormal(const Primitive& prim, const Eigen::Vector3d& p_world, int face) {
  const Eigen::Vector3d p = prim.axes.transpose() * (p_world - prim.centre);
  Eigen::Vector3d n_local = Eigen::Vector3d::Zero();
  switch (prim.shape) {
    case Shape::kSphere:
      n_local = p.normalized();
      break;
    case Shape::kBox:
      n_local[face / 2] = (face & 1) ? 1.0 : -1.0;
      break;
    case Shape::kCylinder:
      if (face == 0) {
        n_local = Eigen::Vector3d(p.x(), 0, p.z()).normalized();
      } else {
        n_local.y() = face == 2 ? 1.0 : -1.0;
      }
      break;
  }
  return prim.axes * n_local;
}

Eigen::Vector2d PrimitiveFaceUv(const Primitive& prim, const Eigen::Vector3d& p_world, int face) {
  const Eigen::Vector3d p = prim.axes.transpose() * (p_world - prim.centre);
  switch (prim.shape) {
    case Shape::kBox: {
      const int axis = face / 2;
      if (axis == 0) return {p.z(), p.y() + prim.half.y()};
      if (axis == 2) return {p.x(), p.y() + prim.half.y()};
      return {p.x(), p.z()};
    }
    case Shape::kCylinder:
      return {std::atan2(p.z(), p.x()) * prim.half.x(), p.y() + prim.half.y()};
    case Shape::kSphere:
      return {std::atan2(p.z(), p.x()) * prim.half.x(), p.y()};
  }
  return {0, 0};
}

void PrimitiveBounds(const Primitive& prim, Eigen::Vector3d* lo, Eigen::Vector3d* hi) {
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();
  switch (prim.shape) {
    case Shape::kSphere:
      extent.setConstant(prim.half.x());
      break;
    case Shape::kBox:
      extent = prim.axes.cwiseAbs() * prim.half;
      break;
    case Shape::kCylinder: {
      // Axis half-segment plus the radius in every direction (conservative).
      const Eigen::Vector3d axis = prim.axes.col(1) * prim.half.y();
      extent = axis.cwiseAbs() + Eigen::Vector3d::Constant(prim.half.x());
      break;
    }
  }
  *lo = prim.centre - extent;
  *hi = prim.centre + extent;
}

Primitive MakeSphere(const Eigen::Vector3d& centre, double radius, int material) {
  Primitive p;
  p.shape = Shape::kSphere;
  p.centre = centre;
  p.half = Eigen::Vector3d::Constant(radius);
  p.material = material;
  return p;
}

Primitive MakeBox(const Eigen::Vector3d& centre, const Eigen::Vector3d& half_extents,
                  double yaw_deg, int material) {
  Primitive p;
  p.shape = Shape::kBox;
  p.centre = centre;
  p.axes = Eigen::AngleAxisd(yaw_deg * 3.14159265358979323846 / 180.0, Eigen::Vector3d::UnitY())
               .toRotationMatrix();
  p.half = half_extents;
  p.material = material;
  return p;
}

Primitive MakeCylinder(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                       int material) {
  Primitive p;
  p.shape = Shape::kCylinder;
  p.centre = 0.5 * (a + b);
  const Eigen::Vector3d y = (b - a).normalized();
  // Any orthonormal frame with local y along the axis.
  const Eigen::Vector3d helper =
      std::abs(y.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d z = helper.cross(y).normalized();
  const Eigen::Vector3d x = y.cross(z);
  p.axes.col(0) = x;
  p.axes.col(1) = y;
  p.axes.col(2) = z;
  p.half = Eigen::Vector3d(radius, 0.5 * (b - a).norm(), radius);
  p.material = material;
  return p;
}

}  // namespace casual3d::synth
