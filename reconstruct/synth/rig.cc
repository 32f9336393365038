#include "reconstruct/synth/rig.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "reconstruct/synth/procedural_texture.h"

namespace casual3d::synth {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// Unit direction for yaw (about +Y, 0 = -Z, positive to the right, +X) and pitch (up).
Eigen::Vector3d Direction(double yaw_rad, double pitch_rad) {
  return {std::cos(pitch_rad) * std::sin(yaw_rad), std::sin(pitch_rad),
          -std::cos(pitch_rad) * std::cos(yaw_rad)};
}

// World-to-camera pose for a camera at `centre` looking along `forward` with
// image rows going down (world -Y) and no roll (camera: X right, Y down, Z forward).
geometry::Pose LookAlong(const Eigen::Vector3d& centre, const Eigen::Vector3d& forward) {
  const Eigen::Vector3d z = forward.normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d cam_to_world;
  cam_to_world.col(0) = x;
  cam_to_world.col(1) = y;
  cam_to_world.col(2) = z;
  geometry::Pose pose;
  const Eigen::Matrix3d R = cam_to_world.transpose();
  pose.rotation = Eigen::Quaterniond(R).normalized();
  pose.translation = -(R * centre);
  return pose;
}

}  // namespace

bool RigKindFromName(const std::string& name, RigKind* kind) {
  if (name == "partial") {
    *kind = RigKind::kPartial;
    return true;
  }
  if (name == "sphere") {
    *kind = RigKind::kSphere;
    return true;
  }
  if (name == "walk-around") {
    *kind = RigKind::kWalkAround;
    return true;
  }
  return false;
}

const char* RigKindName(RigKind kind) {
  switch (kind) {
    case RigKind::kSphere:
      return "sphere";
    case RigKind::kWalkAround:
      return "walk-around";
    case RigKind::kPartial:
      break;
  }
  return "partial";
}

RigOptions RigOptions::Defaults(RigKind kind) {
  RigOptions o;
  o.kind = kind;
  if (kind == RigKind::kSphere) {
    o.num_photos = 50;
    o.fov_x_deg = 110.0;
  } else if (kind == RigKind::kWalkAround) {
    o.num_photos = 12;
    o.yaw_span_deg = 90.0;
  }
  return o;
}

Rig MakeRig(const RigOptions& options, const Eigen::Vector3d& centre) {
  Rig rig;
  rig.camera.camera_id = 1;
  rig.camera.model = geometry::CameraModelId::kPinhole;
  rig.camera.width = options.width;
  rig.camera.height = options.height;
  const double f = 0.5 * options.width / std::tan(0.5 * options.fov_x_deg * kDeg);
  rig.camera.params = {f, f, 0.5 * options.width, 0.5 * options.height};

  // Nominal viewing directions (yaw, pitch) in capture order.
  std::vector<std::pair<double, double>> directions;
  const int n = options.num_photos;
  if (options.kind == RigKind::kWalkAround) {
    // Looking at the subject from the arc, left to right (positions below).
    for (int i = 0; i < n; ++i) {
      directions.emplace_back(n > 1 ? (static_cast<double>(i) / (n - 1) - 0.5) * options.yaw_span_deg : 0.0,
                              0.0);
    }
  } else if (options.kind == RigKind::kPartial) {
    // A grid about as wide as tall (4 x 4 for 16 photos), swept row by row in
    // a serpentine as a person would.
    const int cols = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n)) - 1e-9)));
    const int rows = (n + cols - 1) / cols;
    for (int r = 0; r < rows && static_cast<int>(directions.size()) < n; ++r) {
      const double pitch =
          rows > 1 ? (0.5 - static_cast<double>(r) / (rows - 1)) * options.pitch_span_deg : 0.0;
      for (int k = 0; k < cols && static_cast<int>(directions.size()) < n; ++k) {
        const int c = (r % 2 == 0) ? k : cols - 1 - k;
        const double yaw =
            cols > 1 ? (static_cast<double>(c) / (cols - 1) - 0.5) * options.yaw_span_deg : 0.0;
        directions.emplace_back(yaw, pitch);
      }
    }
  } else {
    // Two rings; the lower ring is offset by half a step for even coverage.
    const int upper = (n + 1) / 2, lower = n - upper;
    for (int i = 0; i < upper; ++i) directions.emplace_back(360.0 * i / upper, options.ring_pitch_deg);
    for (int i = 0; i < lower; ++i) {
      directions.emplace_back(360.0 * (i + 0.5) / lower, -options.ring_pitch_deg);
    }
  }

  for (int i = 0; i < n; ++i) {
    const double yaw = directions[i].first * kDeg, pitch = directions[i].second * kDeg;
    const Eigen::Vector3d radial = Direction(yaw, pitch);
    // Hand-held jitter: a small random rotation of the viewing direction and
    // a roll, and a small offset of the centre.
    auto normal = [&](int k) {
      return HashToNormal(Hash(options.seed, 0x816, i, 2 * k), Hash(options.seed, 0x816, i, 2 * k + 1));
    };
    const double jr = options.jitter_deg * kDeg;
    const Eigen::Vector3d forward = Direction(yaw + jr * normal(0), pitch + jr * normal(1));
    const Eigen::Vector3d offset =
        options.jitter_m * Eigen::Vector3d(normal(2), normal(3), normal(4));
    // Turning rigs sit on a sphere around the centre, looking out; the
    // walk-around one on the circle around the subject, looking in.
    Eigen::Vector3d c = centre + options.radius_m * radial + offset;
    if (options.kind == RigKind::kWalkAround)
      c = centre + options.walk_distance_m * (Direction(0.0, 0.0) - radial) + offset;
    geometry::Pose pose = LookAlong(c, forward);
    // Roll about the optical axis (camera Z).
    const Eigen::Matrix3d roll =
        Eigen::AngleAxisd(jr * normal(5), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3d R = roll * pose.R();
    pose.rotation = Eigen::Quaterniond(R).normalized();
    pose.translation = -(R * c);
    rig.poses.push_back(pose);
  }
  return rig;
}

}  // namespace casual3d::synth
