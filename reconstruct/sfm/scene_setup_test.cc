#include "reconstruct/sfm/scene_setup.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>

namespace casual3d::sfm {
namespace {

using geometry::Pose;
using geometry::SparseModel;

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// World-to-camera pose of a camera at `centre` whose optical axis is `view` and
// whose image up is as close to `up` as possible (built here so that the test
// does not depend on the code it checks).
Pose MakePose(const Eigen::Vector3d& centre, const Eigen::Vector3d& view,
              const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = view.normalized();
  const Eigen::Vector3d y = -(up - up.dot(z) * z).normalized();  // Camera +Y is down.
  const Eigen::Vector3d x = y.cross(z);
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  Pose pose;
  pose.rotation = Eigen::Quaterniond(R);
  pose.translation = -R * centre;
  return pose;
}

geometry::Camera MakeCamera() {
  geometry::Camera cam;
  cam.camera_id = 1;
  cam.model = geometry::CameraModelId::kPinhole;
  cam.width = 640;
  cam.height = 480;
  cam.params = {500, 500, 320, 240};
  return cam;
}

// A world whose up and forward are not the coordinate axes.
struct World {
  Eigen::Matrix3d tilt;
  Eigen::Vector3d up, forward, offset;
  World() {
    tilt = (Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()) *
            Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY()))
               .toRotationMatrix();
    up = tilt * Eigen::Vector3d::UnitY();
    forward = tilt * -Eigen::Vector3d::UnitZ();
    offset = Eigen::Vector3d(3.0, -1.0, 7.5);
  }
  // A point given in a local frame (+X right, +Y up, -Z forward).
  Eigen::Vector3d P(double x, double y, double z) const {
    return tilt * Eigen::Vector3d(x, y, z) + offset;
  }
};

// A partial capture: a 3x3 grid of cameras on a sphere of radius 0.3 m, each
// looking forward with a few degrees of jitter, all observing every point of a
// wall 2..4 m in front.
SparseModel PartialCapture(const World& w, std::vector<double>* true_depths_cam1 = nullptr) {
  SparseModel model;
  model.cameras[1] = MakeCamera();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-3 * kDeg, 3 * kDeg);
  int id = 1;
  for (int r = -1; r <= 1; ++r) {
    for (int c = -1; c <= 1; ++c) {
      geometry::ModelImage image;
      image.image_id = id;
      image.camera_id = 1;
      image.name = "img" + std::to_string(id) + ".jpg";
      const Eigen::Vector3d centre = w.P(0.3 * std::sin(c * 20 * kDeg), 0.3 * std::sin(r * 15 * kDeg), 0);
      const Eigen::Vector3d view =
          w.tilt * Eigen::Vector3d(jitter(rng), jitter(rng), -1.0);
      image.pose = MakePose(centre, view, w.tilt * Eigen::Vector3d(jitter(rng), 1, 0));
      model.images[id] = image;
      ++id;
    }
  }
  uint64_t pid = 1;
  for (int i = 0; i < 100; ++i) {
    geometry::Point3D p;
    p.point3d_id = pid;
    // Depths 2.0 .. 3.98 m in front of the rig, spread sideways.
    p.xyz = w.P(0.01 * (i % 10) - 0.05, 0.01 * (i / 10) - 0.05, -(2.0 + 0.02 * i));
    for (auto& [image_id, image] : model.images) {
      geometry::Observation2D obs;
      obs.point3d_id = pid;
      p.track.push_back({image_id, static_cast<int>(image.points2d.size())});
      image.points2d.push_back(obs);
    }
    model.points[pid] = p;
    ++pid;
  }
  if (true_depths_cam1 != nullptr) {
    const Pose& pose = model.images[1].pose;
    for (const auto& [id, p] : model.points) {
      true_depths_cam1->push_back((pose.R() * p.xyz + pose.translation).z());
    }
  }
  return model;
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) / kDeg;
}

TEST(PanoramaFrameTest, PartialCaptureRecoversUpForwardAndCentre) {
  const World w;
  const SparseModel model = PartialCapture(w);
  PanoramaFrameInfo info;
  const PanoramaFrame frame = ComputePanoramaFrame(model, {}, &info);
  EXPECT_FALSE(info.full_capture);
  EXPECT_GT(info.resultant, 0.99);
  EXPECT_EQ(info.num_cameras, 9);
  // Up and forward within the jitter's average (a few tenths of a degree).
  EXPECT_LT(AngleDeg(info.up, w.up), 1.0);
  EXPECT_LT(AngleDeg(info.forward, w.forward), 1.0);
  // Centre: the mean of the camera centres (computed independently).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& [id, im] : model.images) mean += -(im.pose.R().transpose() * im.pose.translation);
  mean /= 9.0;
  EXPECT_LT((FrameCentre(frame) - mean).norm(), 1e-12);
  EXPECT_NEAR(info.rig_radius, 0.08, 0.04);

  const Eigen::Matrix3d R = FrameRotation(frame);
  EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  // A point straight ahead maps to -Z, one above to +Y, one to the right to +X.
  const Eigen::Vector3d ahead = WorldToPanorama(frame, FrameCentre(frame) + 2.0 * info.forward);
  EXPECT_NEAR(ahead.z(), -2.0, 1e-9);
  EXPECT_NEAR(ahead.x(), 0.0, 1e-9);
  const Eigen::Vector3d above = WorldToPanorama(frame, FrameCentre(frame) + info.up);
  EXPECT_NEAR(above.y(), 1.0, 1e-9);
  const Eigen::Vector3d right_world = info.forward.cross(info.up);
  const Eigen::Vector3d right = WorldToPanorama(frame, FrameCentre(frame) + right_world);
  EXPECT_NEAR(right.x(), 1.0, 1e-9);
}

TEST(PanoramaFrameTest, FullCaptureUsesFirstCameraForward) {
  const World w;
  SparseModel model;
  model.cameras[1] = MakeCamera();
  for (int k = 0; k < 12; ++k) {
    geometry::ModelImage image;
    image.image_id = 10 + k;
    image.camera_id = 1;
    const double a = (k * 30 + 17) * kDeg;
    const Eigen::Vector3d out = w.tilt * Eigen::Vector3d(std::sin(a), 0, -std::cos(a));
    image.pose = MakePose(w.offset + 0.3 * out, out, w.up);
    model.images[image.image_id] = image;
  }
  PanoramaFrameInfo info;
  const PanoramaFrame frame = ComputePanoramaFrame(model, {}, &info);
  EXPECT_TRUE(info.full_capture);
  EXPECT_LT(info.resultant, 0.01);
  EXPECT_LT(AngleDeg(info.up, w.up), 1e-6);
  const Eigen::Vector3d first = w.tilt * Eigen::Vector3d(std::sin(17 * kDeg), 0, -std::cos(17 * kDeg));
  EXPECT_LT(AngleDeg(info.forward, first), 1e-6);
  EXPECT_LT((FrameCentre(frame) - w.offset).norm(), 1e-9);
  EXPECT_NEAR(info.rig_radius, 0.3, 1e-9);
}

TEST(PanoramaFrameTest, RobustCentreIgnoresAStrayCamera) {
  const World w;
  SparseModel model = PartialCapture(w);
  geometry::ModelImage stray = model.images[1];
  stray.image_id = 99;
  stray.pose = MakePose(w.P(5, 0, 0), w.forward, w.up);  // 5 m to the side.
  model.images[99] = stray;
  PanoramaFrameOptions options;
  const Eigen::Vector3d mean_centre = FrameCentre(ComputePanoramaFrame(model, options));
  options.robust_centre = true;
  const Eigen::Vector3d robust_centre = FrameCentre(ComputePanoramaFrame(model, options));
  EXPECT_GT((mean_centre - w.offset).norm(), 0.4);    // The mean moves 0.5 m.
  EXPECT_LT((robust_centre - w.offset).norm(), 0.1);  // The median barely moves.
}

TEST(PanoramaFrameTest, RejectsBadInput) {
  EXPECT_THROW(ComputePanoramaFrame(SparseModel{}, {}), std::runtime_error);
  PanoramaFrameOptions bad;
  bad.min_partial_resultant = 1.5;
  EXPECT_FALSE(bad.Check().ok());
  EXPECT_NE(bad.Check().message().find("min_partial_resultant"), std::string::npos);
  EXPECT_THROW(ComputePanoramaFrame(PartialCapture(World()), bad), std::invalid_argument);
  // Two cameras rolled upside down relative to each other: no up.
  SparseModel model;
  model.cameras[1] = MakeCamera();
  model.images[1].pose = MakePose({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
  model.images[2].pose = MakePose({0.1, 0, 0}, {0, 0, -1}, {0, -1, 0});
  EXPECT_THROW(ComputePanoramaFrame(model, {}), std::runtime_error);
}

TEST(DepthRangeTest, PercentilesWithMargins) {
  const World w;
  std::vector<double> depths;
  const SparseModel model = PartialCapture(w, &depths);
  std::sort(depths.begin(), depths.end());
  const auto ranges = ComputeDepthRanges(model, {});
  ASSERT_EQ(ranges.size(), 9u);
  const DepthRange& r = ranges.at(1);
  EXPECT_EQ(r.name, "img1.jpg");
  EXPECT_EQ(r.source, "observed");
  EXPECT_EQ(r.num_points, 100);
  // Interpolated 2nd and 98th percentiles of the 100 depths, times 0.8 / 1.25.
  const double p02 = depths[1] + 0.98 * (depths[2] - depths[1]);
  const double p98 = depths[97] + 0.02 * (depths[98] - depths[97]);
  EXPECT_NEAR(r.near_m, 0.8 * p02, 1e-9);
  EXPECT_NEAR(r.far_m, 1.25 * p98, 1e-9);
  // And the bounds contain the scene (2..4 m from the rig).
  for (const auto& [id, range] : ranges) {
    EXPECT_GT(range.near_m, 1.4);
    EXPECT_LT(range.near_m, 2.0);
    EXPECT_GT(range.far_m, 4.0);
    EXPECT_LT(range.far_m, 5.2);
  }
}

TEST(DepthRangeTest, OutlierPointsAreTrimmed) {
  const World w;
  SparseModel model = PartialCapture(w);
  // One wild point 1 km away seen by everyone does not move far by much.
  geometry::Point3D far_point;
  far_point.point3d_id = 1000;
  far_point.xyz = w.P(0, 0, -1000);
  for (auto& [id, image] : model.images) {
    geometry::Observation2D obs;
    obs.point3d_id = 1000;
    image.points2d.push_back(obs);
  }
  model.points[1000] = far_point;
  const auto ranges = ComputeDepthRanges(model, {});
  EXPECT_LT(ranges.at(5).far_m, 5.2);
}

TEST(DepthRangeTest, FallbacksForPhotosWithFewObservations) {
  const World w;
  SparseModel model = PartialCapture(w);
  // Photo 2 observes nothing but looks at the wall: frustum fallback.
  model.images[2].points2d.clear();
  // Photo 3 observes nothing and looks backwards: global fallback.
  model.images[3].points2d.clear();
  const Eigen::Vector3d c3 = -(model.images[3].pose.R().transpose() * model.images[3].pose.translation);
  model.images[3].pose = MakePose(c3, -w.forward, w.up);
  const auto ranges = ComputeDepthRanges(model, {});
  ASSERT_EQ(ranges.size(), 9u);
  EXPECT_EQ(ranges.at(2).source, "frustum");
  EXPECT_EQ(ranges.at(2).num_points, 100);
  EXPECT_NEAR(ranges.at(2).near_m, ranges.at(1).near_m, 0.1);
  EXPECT_EQ(ranges.at(3).source, "global");
  EXPECT_EQ(ranges.at(3).num_points, 0);
  EXPECT_GT(ranges.at(3).near_m, 1.4);
  EXPECT_LT(ranges.at(3).far_m, 5.2);
}

// Adds a point at local (x, y, z) observed by the photos `seen_by`.
void AddPoint(const World& w, uint64_t id, double x, double y, double z, const std::vector<int>& seen_by,
              SparseModel* model) {
  geometry::Point3D p;
  p.point3d_id = id;
  p.xyz = w.P(x, y, z);
  for (int image_id : seen_by) {
    geometry::ModelImage& image = model->images.at(image_id);
    geometry::Observation2D obs;
    obs.point3d_id = id;
    p.track.push_back({image_id, static_cast<int>(image.points2d.size())});
    image.points2d.push_back(obs);
  }
  model->points[id] = p;
}

TEST(DepthRangeTest, NearObjectThatOtherPhotosSawBoundsTheNearDepth) {
  const World w;
  SparseModel model = PartialCapture(w);
  // A box 0.8 m in front of the rig: photos 1-8 matched 6 of its points, photo
  // 9 none, though it sees them. A stray point 0.3 m away that only two
  // photos matched does not count.
  for (int i = 0; i < 6; ++i) AddPoint(w, 2000 + i, 0.02 * i - 0.05, 0.01 * i, -0.8, {1, 2, 3, 4, 5, 6, 7, 8}, &model);
  AddPoint(w, 3000, 0.0, 0.0, -0.3, {1, 2}, &model);
  auto camera_depth = [&](int image_id, uint64_t point_id) {
    const geometry::Pose& pose = model.images.at(image_id).pose;
    return (pose.R() * model.points.at(point_id).xyz + pose.translation).z();
  };
  std::vector<double> box;
  for (int i = 0; i < 6; ++i) box.push_back(camera_depth(9, 2000 + i));
  std::sort(box.begin(), box.end());
  const auto ranges = ComputeDepthRanges(model, {});
  EXPECT_EQ(ranges.at(9).source, "observed");
  EXPECT_EQ(ranges.at(9).num_points, 100);
  EXPECT_NEAR(ranges.at(9).near_m, 0.8 * box[4], 1e-9);  // The 5th nearest, times 0.8.
  // Off: photo 9 keeps the range of its own points, behind the box.
  DepthRangeOptions off;
  off.frustum_near_points = 0;
  EXPECT_GT(ComputeDepthRanges(model, off).at(9).near_m, 1.4);
}

TEST(DepthRangeTest, RejectsBadOptionsAndEmptyModels) {
  DepthRangeOptions options;
  options.near_percentile = 0.7;
  EXPECT_NE(options.Check().message().find("near_percentile"), std::string::npos);
  EXPECT_THROW(ComputeDepthRanges(PartialCapture(World()), options), std::invalid_argument);
  options = {};
  options.far_margin = 0.5;
  EXPECT_NE(options.Check().message().find("far_margin"), std::string::npos);
  EXPECT_TRUE(DepthRangeOptions{}.Check().ok());
  EXPECT_THROW(ComputeDepthRanges(SparseModel{}, {}), std::runtime_error);
  SparseModel no_points = PartialCapture(World());
  no_points.points.clear();
  EXPECT_THROW(ComputeDepthRanges(no_points, {}), std::runtime_error);
}

std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "/scene_setup_" + std::to_string(::getpid()) + "_" + name;
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

TEST(SceneSetupFilesTest, RoundTrip) {
  const World w;
  const SparseModel model = PartialCapture(w);
  const auto ranges = ComputeDepthRanges(model, {});
  const std::string ranges_path = TempPath("depth_ranges.json");
  WriteDepthRanges(ranges, ranges_path);
  const auto read = ReadDepthRanges(ranges_path);
  ASSERT_EQ(read.size(), ranges.size());
  for (const auto& [id, r] : ranges) {
    EXPECT_EQ(read.at(id).name, r.name);
    EXPECT_DOUBLE_EQ(read.at(id).near_m, r.near_m);
    EXPECT_DOUBLE_EQ(read.at(id).far_m, r.far_m);
    EXPECT_EQ(read.at(id).source, r.source);
  }
  PanoramaFrameInfo info;
  const PanoramaFrame frame = ComputePanoramaFrame(model, {}, &info);
  const std::string frame_path = TempPath("frame.json");
  WritePanoramaFrame(frame, frame_path, &info);
  const PanoramaFrame back = ReadPanoramaFrame(frame_path);
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(back.centre[k], frame.centre[k]);
  for (int k = 0; k < 9; ++k) EXPECT_DOUBLE_EQ(back.rotation[k], frame.rotation[k]);
  std::remove(ranges_path.c_str());
  std::remove(frame_path.c_str());
}

TEST(SceneSetupFilesTest, ReadersRejectBadFiles) {
  const std::string path = TempPath("bad.json");
  auto expect_error = [&](const std::string& text, const std::string& needle, bool frame) {
    WriteText(path, text);
    try {
      if (frame) {
        ReadPanoramaFrame(path);
      } else {
        ReadDepthRanges(path);
      }
      ADD_FAILURE() << "no error for " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  expect_error("{", "not valid JSON", true);
  expect_error(R"({"format":"casual3d-panorama-frame","version":"2.0"})", "major version 2", true);
  expect_error(R"({"format":"other","version":"1.0"})", "'format'", true);
  expect_error(R"({"format":"casual3d-panorama-frame","version":"1.0","centre":[0,0,0],
                   "rotation":[1,0,0,0,1,0,0,0,2]})",
               "not a rotation", true);
  expect_error(R"({"format":"casual3d-panorama-frame","version":"1.0","centre":[0,0],
                   "rotation":[1,0,0,0,1,0,0,0,1]})",
               "'centre'", true);
  expect_error(R"({"format":"casual3d-depth-ranges","version":"1.3","images":[
                   {"image_id":1,"name":"a","near_m":2,"far_m":1}]})",
               "near_m < far_m", false);
  expect_error(R"({"format":"casual3d-depth-ranges","version":"1.0","images":[
                   {"image_id":1,"name":"a","far_m":1}]})",
               "'near_m'", false);
  // Unknown fields and a newer minor version are fine.
  WriteText(path, R"({"format":"casual3d-depth-ranges","version":"1.7","extra":1,"images":[
                   {"image_id":4,"name":"a","near_m":1,"far_m":3,"colour":"red"}]})");
  EXPECT_DOUBLE_EQ(ReadDepthRanges(path).at(4).far_m, 3.0);
  EXPECT_THROW(ReadDepthRanges(TempPath("missing.json")), std::runtime_error);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace casual3d::sfm
