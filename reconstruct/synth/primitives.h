#pragma once

// Closed convex solids for the synthetic scene: spheres, oriented boxes and
// oriented capped cylinders (thin rods are cylinders of small radius). Each
// solid intersects a ray in one interval [t_in, t_out]; the scene treats its
// solids as a union, which defines the first and second surfaces along a ray.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace casual3d::synth {

enum class Shape : int { kSphere = 0, kBox = 1, kCylinder = 2 };

struct Primitive {
  Shape shape = Shape::kSphere;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // World, metres.
  // Columns: the solid's local x, y, z axes in world coordinates (orthonormal).
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  // Sphere: radius = half.x(). Box: half extents. Cylinder: radius = half.x(),
  // half length along local y = half.y().
  Eigen::Vector3d half = Eigen::Vector3d::Ones();
  int material = 0;  // Index into the scene's materials.
  bool is_moving = false;  // The object that moves during the capture.
  // The ground: solid matter continues below it, so a ray that enters it has
  // no second surface (see Scene::TraceTwoSurfaces).
  bool is_ground = false;
};

// A ray-solid intersection interval. `face` identifies the entry face (box:
// 0..5 = -x,+x,-y,+y,-z,+z; cylinder: 0 side, 1 bottom cap, 2 top cap; sphere 0).
struct Interval {
  double t_in = 0;
  double t_out = 0;
  int face_in = 0;
};

// Intersects the ray origin + t * dir (dir need not be unit; t is in units of
// |dir|) with the solid. Returns false if the ray's line misses it or the whole
// interval lies at t < 0.
bool IntersectPrimitive(const Primitive& prim, const Eigen::Vector3d& origin,
                        const Eigen::Vector3d& dir, Interval* interval);

// The outward unit normal (world) at a surface point on the given face.
Eigen::Vector3d PrimitiveNormal(const Primitive& prim, const Eigen::Vector3d& p_world, int face);

// Face coordinates in metres at a surface point (for brick and window
// textures): horizontal along the face and vertical (local y) on side faces.
Eigen::Vector2d PrimitiveFaceUv(const Primitive& prim, const Eigen::Vector3d& p_world, int face);

// World-space axis-aligned bounds of the solid.
void PrimitiveBounds(const Primitive& prim, Eigen::Vector3d* lo, Eigen::Vector3d* hi);

// Helpers to build solids. `yaw_deg` rotates about world +Y.
Primitive MakeSphere(const Eigen::Vector3d& centre, double radius, int material);
Primitive MakeBox(const Eigen::Vector3d& centre, const Eigen::Vector3d& half_extents,
                  double yaw_deg, int material);
// A cylinder from `a` to `b` (any direction) of the given radius.
Primitive MakeCylinder(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                       int material);

}  // namespace casual3d::synth
