#pragma once

// A procedural scene: closed convex solids (primitives.h) with procedural
// materials (procedural_texture.h), a bounding volume hierarchy for ray
// queries, a sun and a sky at infinity. The solids form a union: the first
// surface along a ray is where it first enters solid matter and the second
// surface is where it next enters solid matter after leaving it (so the ground
// under a box or the inside of a sphere never count as surfaces). The ground
// is solid all the way down: nothing is behind it.
//
// Units: metres. World frame: +Y up (the ground is the plane y = 0).

#include <vector>

#include <Eigen/Core>

#include "reconstruct/synth/primitives.h"
#include "reconstruct/synth/procedural_texture.h"

namespace casual3d::synth {

// A ray hit. `t` is the distance along the (unit) ray direction, in metres.
struct Hit {
  double t = 0;
  int primitive = -1;
  int face = 0;
  // An id that differs between primitives and between the flat faces of one
  // primitive (for edge detection in anti-aliasing).
  int SurfaceId() const { return primitive * 8 + face; }
};

class Scene {
 public:
  Scene() = default;
  // `primitives` with `materials` (Primitive::material indexes it). Builds the BVH.
  Scene(std::vector<Primitive> primitives, std::vector<Material> materials);

  // The same scene with every moving primitive displaced by `offset_m` (world).
  Scene Displaced(const Eigen::Vector3d& offset_m) const;

  // The nearest surface along origin + t * dir (dir unit) with t > t_min.
  // Returns false for sky.
  bool TraceClosest(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min,
                    Hit* hit) const;

  // The first and second surfaces (see above) along a ray; returns how many
  // exist (0: sky, 1: one surface, 2: both). With 1, `*into_ground` tells
  // whether the ray ends in the ground (nothing behind: the earth is solid)
  // rather than leaving into the sky.
  int TraceTwoSurfaces(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, Hit* first,
                       Hit* second, bool* into_ground) const;

  // Outward unit normal at a hit.
  Eigen::Vector3d Normal(const Hit& hit, const Eigen::Vector3d& origin,
                         const Eigen::Vector3d& dir) const;

  // Linear radiance (exposure 1) leaving the surface at `hit` towards the ray's
  // origin. `pixel_angle_rad` is the angular size of the pixel, used to
  // band-limit the textures.
  Eigen::Vector3d Shade(const Hit& hit, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                        double pixel_angle_rad) const;

  // Linear radiance of the sky in direction `dir` (unit): a gradient from a
  // pale horizon to a deeper zenith blue, plus a soft glow around the sun.
  Eigen::Vector3d Sky(const Eigen::Vector3d& dir) const;

  const std::vector<Primitive>& primitives() const { return primitives_; }
  const std::vector<Material>& materials() const { return materials_; }
  const Eigen::Vector3d& sun_direction() const { return sun_direction_; }

 private:
  struct Node {
    Eigen::Vector3d lo, hi;
    int left = -1;   // Child index, or -1 for a leaf.
    int right = -1;
    int first = 0;   // Leaf: range in order_.
    int count = 0;
  };
  int Build(int first, int count, int depth);
  template <typename Visit>
  void Traverse(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                Visit&& visit) const;

  std::vector<Primitive> primitives_;
  std::vector<Material> materials_;
  std::vector<int> order_;       // Primitive indices in BVH leaf order.
  std::vector<int> unbounded_;   // Tested for every ray: moving objects and huge solids.
  std::vector<Node> nodes_;
  std::vector<Eigen::Vector3d> bounds_lo_, bounds_hi_;
  Eigen::Vector3d sun_direction_ = Eigen::Vector3d(0.45, 0.75, 0.35).normalized();
};

}  // namespace casual3d::synth
