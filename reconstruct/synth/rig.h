#pragma once

// Capture rigs: where the photos of a synthetic capture are taken from.
//   partial: a phone held at arm's length and swept over a grid (about 4 x 4)
//     of directions in front of the user: camera centres on a sphere of
//     `radius_m` around the rig centre, each camera looking outwards along its
//     radius, so the grid spans about +-27 degrees of yaw and +-18 of pitch
//     around forward (-Z); 65 degrees horizontal field of view by default.
//   sphere: a DSLR turned on a monopod: two rings (pitched up and down by
//     `ring_pitch_deg`) of photos all around, 110 degrees horizontal field of
//     view by default, full 360 degree coverage.
//   walk-around: what a 3D photo is not made from, for the capture advice: a
//     person walking around a subject `walk_distance_m` ahead of the rig
//     centre, on a circle of that radius through the rig centre, over
//     `yaw_span_deg` (default 90 degrees) of it, each photo looking at the
//     subject; 12 photos by default.
// All add a small hand-held jitter (seeded) to every orientation and position.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "format/status.h"
#include "reconstruct/geometry/camera.h"
#include "reconstruct/geometry/pose.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::synth {

enum class RigKind { kPartial, kSphere, kWalkAround };

// "partial" / "sphere" / "walk-around"; false for anything else.
bool RigKindFromName(const std::string& name, RigKind* kind);
const char* RigKindName(RigKind kind);

struct RigOptions {
  RigKind kind = RigKind::kPartial;
  int width = 1152;          // Photo width, pixels.
  int height = 864;          // Photo height, pixels.
  int num_photos = 16;       // > 0; partial: 16 (4 x 4), sphere: 50 (2 x 25), walk-around: 12.
  double fov_x_deg = 65.0;   // Horizontal field of view, degrees, (10, 150).
  double radius_m = 0.3;     // Camera centres' distance from the rig centre, metres, [0, 2].
  double yaw_span_deg = 54.0;    // partial: yaw range of the grid; walk-around: of the arc; degrees.
  double pitch_span_deg = 36.0;  // partial: pitch range of the grid, degrees.
  double ring_pitch_deg = 22.0;  // sphere: pitch of the upper (+) and lower (-) ring, degrees.
  double walk_distance_m = 1.3;  // walk-around: the subject's distance ahead, metres, [0.3, 20].
  double jitter_deg = 1.0;   // Hand-held rotation jitter (standard deviation), degrees.
  double jitter_m = 0.01;    // Hand-held position jitter (standard deviation), metres.
  uint64_t seed = 1;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("kind", o.kind, R::Closed(0, 2), "Rig: partial, sphere or walk-around");
    v.Field("width", o.width, R::Closed(16, 16384), "Photo width, pixels");
    v.Field("height", o.height, R::Closed(16, 16384), "Photo height, pixels");
    v.Field("num_photos", o.num_photos, R::Closed(2, 1000), "Number of photos");
    v.Field("fov_x_deg", o.fov_x_deg, R::Open(10, 150), "Horizontal field of view, degrees");
    v.Field("radius_m", o.radius_m, R::Closed(0, 2),
            "Camera centres' distance from the rig centre, metres");
    v.Field("yaw_span_deg", o.yaw_span_deg, R::Closed(0, 180),
            "partial: yaw range of the grid; walk-around: of the arc; degrees");
    v.Field("pitch_span_deg", o.pitch_span_deg, R::Closed(0, 120),
            "partial: pitch range of the grid, degrees");
    v.Field("ring_pitch_deg", o.ring_pitch_deg, R::Closed(0, 60),
            "sphere: pitch of the upper (+) and lower (-) ring, degrees");
    v.Field("walk_distance_m", o.walk_distance_m, R::Closed(0.3, 20),
            "walk-around: the subject's distance ahead, metres");
    v.Field("jitter_deg", o.jitter_deg, R::Closed(0, 10),
            "Hand-held rotation jitter (standard deviation), degrees");
    v.Field("jitter_m", o.jitter_m, R::Closed(0, 0.2),
            "Hand-held position jitter (standard deviation), metres");
    v.Field("seed", o.seed, R::Any(), "Seed of the jitter");
  }

  // The defaults of a rig kind (size, photo count, field of view).
  static RigOptions Defaults(RigKind kind);
  Status Check() const { return util::CheckFields(*this); }  // Names the field and its range.
};

struct Rig {
  geometry::Camera camera;            // PINHOLE, shared by all photos (camera_id 1).
  std::vector<geometry::Pose> poses;  // World to camera, in capture order.
};

// Lays out the rig around `centre` (world, metres); world +Y is up and the rig
// faces world -Z. Precondition: options.Check() is ok.
Rig MakeRig(const RigOptions& options, const Eigen::Vector3d& centre);

}  // namespace casual3d::synth
