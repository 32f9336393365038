#include "reconstruct/synth/clip.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/synth/procedural_texture.h"
#include "reconstruct/synth/render_photo.h"
#include "reconstruct/util/log.h"

namespace casual3d::synth {
namespace {

// Uniform Catmull-Rom spline through `p` at key time `s` in [0, K - 1]; the
// ends are extended by reflection (p[-1] = 2 p[0] - p[1]), so the curve
// leaves the first key and reaches the last one heading along the first and
// last intervals.
Eigen::Vector3d CatmullRom(const std::vector<Eigen::Vector3d>& p, double s) {
  const int k = static_cast<int>(p.size());
  const int i = std::clamp(static_cast<int>(std::floor(s)), 0, k - 2);
  const double u = s - i;
  const auto at = [&](int j) -> Eigen::Vector3d {
    if (j < 0) return 2.0 * p[0] - p[1];
    if (j >= k) return 2.0 * p[k - 1] - p[k - 2];
    return p[j];
  };
  const Eigen::Vector3d p0 = at(i - 1), p1 = at(i), p2 = at(i + 1), p3 = at(i + 2);
  return 0.5 * (2.0 * p1 + (p2 - p0) * u + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u * u +
                (3.0 * p1 - p0 - 3.0 * p2 + p3) * u * u * u);
}

// The rotation nearest (Frobenius) to the mean of `rotations`.
Eigen::Matrix3d ChordalMean(const std::vector<Eigen::Matrix3d>& rotations) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const Eigen::Matrix3d& r : rotations) sum += r;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  fix(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * fix * svd.matrixV().transpose();
}

Eigen::Vector3d RotationVector(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d FromRotationVector(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

}  // namespace

std::string ClipFrameName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%06d.jpg", index);
  return name;
}

std::vector<geometry::Pose> ClipPath(const std::vector<geometry::Pose>& keys, int num_frames,
                                     std::vector<double>* key_times) {
  const int k = static_cast<int>(keys.size());
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<Eigen::Vector3d> centres;
  for (const geometry::Pose& p : keys) {
    rotations.push_back(p.R());
    centres.push_back(p.Center());
  }
  // Orientations as rotation vectors about their mean: the keys of a capture
  // span well under 90 degrees, where this chart is smooth and one to one.
  const Eigen::Matrix3d mean = ChordalMean(rotations);
  std::vector<Eigen::Vector3d> vectors;
  for (const Eigen::Matrix3d& r : rotations)
    vectors.push_back(RotationVector(r * mean.transpose()));
  std::vector<geometry::Pose> path;
  if (key_times) key_times->clear();
  for (int f = 0; f < num_frames; ++f) {
    const double s = num_frames > 1 ? static_cast<double>(f) * (k - 1) / (num_frames - 1) : 0.0;
    const Eigen::Matrix3d r = FromRotationVector(CatmullRom(vectors, s)) * mean;
    path.push_back(geometry::Pose::FromCenter(r, CatmullRom(centres, s)));
    if (key_times) key_times->push_back(s);
  }
  return path;
}

ClipSummary WriteClip(const ClipOptions& options, const RigOptions& rig_options,
                      const Eigen::Vector3d& centre, const Scene& scene, const Rig& photo_rig,
                      const std::vector<std::string>& photo_names, const std::string& dir) {
  const auto start = std::chrono::steady_clock::now();
  // A second take of the same sweep: the rig's nominal directions with
  // jitter of its own.
  RigOptions take_options = rig_options;
  take_options.seed = Hash(options.seed, 0xC11F);
  const Rig take = MakeRig(take_options, centre);
  std::vector<double> key_times;
  const std::vector<geometry::Pose> path = ClipPath(take.poses, options.num_frames, &key_times);
  // Auto exposure: a smooth drift through a random level per key, in stops.
  std::vector<Eigen::Vector3d> stops;
  for (size_t k = 0; k < take.poses.size(); ++k) {
    const double u = HashToUnit(Hash(options.seed, 0xC11FE, k));
    stops.emplace_back(options.exposure_jitter_stops * (2.0 * u - 1.0), 0.0, 0.0);
  }

  io::CreateDirectories(dir + "/video/sparse");
  RenderOptions render;
  render.edge_samples = options.edge_samples;
  render.num_threads = options.num_threads;
  util::Progress progress("synth: rendering video frames", options.num_frames);
  for (int f = 0; f < options.num_frames; ++f) {
    const Eigen::Vector3d offset = options.moving_object
                                       ? Eigen::Vector3d(options.moving_step_m * key_times[f], 0, 0)
                                       : Eigen::Vector3d::Zero();
    const PhotoRender r = RenderPhoto(scene.Displaced(offset), photo_rig.camera, path[f], render);
    DevelopOptions develop;
    const double s = std::clamp(CatmullRom(stops, key_times[f]).x(), -options.exposure_jitter_stops,
                                options.exposure_jitter_stops);
    develop.exposure = std::exp2(s);
    develop.noise_sigma = options.noise_sigma;
    develop.seed = Hash(options.seed, 0xC11F401, f);
    const Image8 frame = Develop(r.radiance, develop);
    io::WriteFileAtomic(dir + "/video/" + ClipFrameName(f),
                        io::EncodeJpeg(frame.view(), {options.jpeg_quality}));
    progress.Advance();
  }
  progress.Finish();

  // Ground truth: the photos (ids 1..P) and the frames (P+1..P+N), one camera.
  geometry::SparseModel model;
  model.cameras[photo_rig.camera.camera_id] = photo_rig.camera;
  const int num_photos = static_cast<int>(photo_names.size());
  const auto add = [&](int id, const std::string& name, const geometry::Pose& pose) {
    geometry::ModelImage image;
    image.image_id = id;
    image.camera_id = photo_rig.camera.camera_id;
    image.name = name;
    image.pose = pose;
    model.images[id] = image;
  };
  for (int i = 0; i < num_photos; ++i) add(i + 1, photo_names[i], photo_rig.poses[i]);
  for (int f = 0; f < options.num_frames; ++f) add(num_photos + 1 + f, ClipFrameName(f), path[f]);
  geometry::WriteModelText(model, dir + "/video/sparse");
  geometry::WriteModelBinary(model, dir + "/video/sparse");

  ClipSummary summary;
  summary.num_frames = options.num_frames;
  for (int i = 0; i < num_photos; ++i) {
    NearestFrame nearest;
    nearest.photo = photo_names[i];
    nearest.distance_m = std::numeric_limits<double>::infinity();
    for (int f = 0; f < options.num_frames; ++f) {
      const double d = (path[f].Center() - photo_rig.poses[i].Center()).norm();
      if (d >= nearest.distance_m) continue;
      nearest.distance_m = d;
      nearest.frame = ClipFrameName(f);
      nearest.angle_deg = geometry::RotationAngleDeg(path[f].rotation, photo_rig.poses[i].rotation);
    }
    summary.nearest.push_back(nearest);
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace casual3d::synth
