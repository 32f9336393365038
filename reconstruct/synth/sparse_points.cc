#include "reconstruct/synth/sparse_points.h"

#include <cmath>

#include "base/parallel_for.h"
#include "reconstruct/synth/procedural_texture.h"
#include "reconstruct/synth/srgb.h"

namespace casual3d::synth {
namespace {

struct Candidate {
  Eigen::Vector3d xyz;
  uint8_t rgb[3];
  std::vector<std::pair<int, Eigen::Vector2d>> observations;  // Photo index, pixel.
};

}  // namespace

geometry::SparseModel MakeGroundTruthModel(const std::vector<Scene>& scenes, const Rig& rig,
                                           const std::vector<std::string>& names,
                                           const SparsePointOptions& options) {
  const geometry::Camera& cam = rig.camera;
  const int n = static_cast<int>(rig.poses.size());
  const double fx = cam.FocalX(), fy = cam.FocalY(), cx = cam.PrincipalX(), cy = cam.PrincipalY();
  std::vector<Eigen::Matrix3d> R(n);
  std::vector<Eigen::Vector3d> centres(n);
  for (int i = 0; i < n; ++i) {
    R[i] = rig.poses[i].R();
    centres[i] = -(R[i].transpose() * rig.poses[i].translation);
  }
  const int gx = cam.width / options.step_px, gy = cam.height / options.step_px;

  // One task per (photo, grid row): candidates are collected per task and
  // concatenated in task order, so the model is independent of threading.
  const int tasks = n * gy;
  std::vector<std::vector<Candidate>> per_task(tasks);
  base::ParallelFor(0, tasks, base::ResolveThreads(options.num_threads), [&](int64_t task64) {
    const int task = static_cast<int>(task64);
    const int i = task / gy, row = task % gy;
    for (int col = 0; col < gx; ++col) {
      const uint64_t h = Hash(options.seed, 0x5BA85E, task, col);
      const double u = (col + 0.1 + 0.8 * HashToUnit(Hash(h, 1))) * options.step_px;
      const double v = (row + 0.1 + 0.8 * HashToUnit(Hash(h, 2))) * options.step_px;
      const Eigen::Vector3d d_cam((u - cx) / fx, (v - cy) / fy, 1.0);
      const Eigen::Vector3d dir = (R[i].transpose() * d_cam).normalized();
      Hit hit;
      if (!scenes[i].TraceClosest(centres[i], dir, 1e-6, &hit)) continue;  // Sky.
      if (scenes[i].primitives()[hit.primitive].is_moving) continue;      // Not static.
      Candidate c;
      c.xyz = centres[i] + hit.t * dir;
      const Eigen::Vector3d color = scenes[i].Shade(hit, centres[i], dir, 1.0 / fx);
      for (int k = 0; k < 3; ++k) c.rgb[k] = LinearToSrgb8(color[k]);
      for (int j = 0; j < n; ++j) {
        const Eigen::Vector3d p = R[j] * c.xyz + rig.poses[j].translation;
        if (p.z() <= 1e-6) continue;
        const Eigen::Vector2d px(fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy);
        if (px.x() < 0 || px.y() < 0 || px.x() >= cam.width || px.y() >= cam.height) continue;
        const Eigen::Vector3d to_point = c.xyz - centres[j];
        const double dist = to_point.norm();
        Hit hj;
        if (!scenes[j].TraceClosest(centres[j], to_point / dist, 1e-6, &hj)) continue;
        if (std::abs(hj.t - dist) > 1e-4 * dist + 1e-5) continue;  // Occluded.
        c.observations.emplace_back(j, px);
      }
      if (static_cast<int>(c.observations.size()) >= options.min_track) {
        per_task[task].push_back(std::move(c));
      }
    }
  });

  geometry::SparseModel model;
  model.cameras[cam.camera_id] = cam;
  for (int i = 0; i < n; ++i) {
    geometry::ModelImage& image = model.images[i + 1];
    image.image_id = i + 1;
    image.camera_id = cam.camera_id;
    image.name = names[i];
    image.pose = rig.poses[i];
  }
  uint64_t next_id = 1;
  for (const auto& list : per_task) {
    for (const Candidate& c : list) {
      geometry::Point3D& point = model.points[next_id];
      point.point3d_id = next_id;
      point.xyz = c.xyz;
      for (int k = 0; k < 3; ++k) point.rgb[k] = c.rgb[k];
      point.error = 0.0;
      for (const auto& [j, px] : c.observations) {
        geometry::ModelImage& image = model.images[j + 1];
        geometry::Observation2D obs;
        obs.xy = px;
        obs.point3d_id = next_id;
        point.track.push_back({j + 1, static_cast<int>(image.points2d.size())});
        image.points2d.push_back(obs);
      }
      ++next_id;
    }
  }
  return model;
}

}  // namespace casual3d::synth
