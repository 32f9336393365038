// Accuracy of the sparse stage with the real COLMAP (slow: minutes
// each on 2 cores): the default synthetic partial capture against its ground
// truth, and the real captures fern (LLFF poses) and fountain-P11 (Strecha's
// ground-truth cameras) from ../shared/datasets, skipped when absent.

#include <dirent.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/sfm/reference_poses.h"
#include "reconstruct/sfm/sparse_stage.h"
#include "reconstruct/synth/synth.h"

namespace casual3d::sfm {
namespace {

namespace fs = std::filesystem;

std::string DatasetDir(const std::string& name) {
  const char* src = std::getenv("CASUAL3D_SOURCE_DIR");
  const fs::path dir = fs::path(src != nullptr ? src : ".") / ".." / "shared" / "datasets" / name;
  return fs::is_directory(dir) ? dir.string() : "";
}

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("sparse_accuracy_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::map<std::string, geometry::Pose> PosesOf(const geometry::SparseModel& model) {
  std::map<std::string, geometry::Pose> poses;
  for (const auto& [id, image] : model.images) poses[image.name] = image.pose;
  return poses;
}

SparseStageOptions DefaultOptions() {
  SparseStageOptions options;
  options.num_threads = 2;
  return options;
}

// Runs the stage and checks the output layout; returns the undistorted model.
geometry::SparseModel RunAndRead(const std::string& input, const fs::path& out,
                                 const SparseStageOptions& options, SparseStageResult* result) {
  *result = RunSparseStage(input, out.string(), options);
  std::printf("%s timings:", input.c_str());
  for (const auto& [step, seconds] : result->timings_s) std::printf(" %s %.1f s", step.c_str(), seconds);
  std::printf("\n");
  for (const char* f : {"frame.json", "depth_ranges.json", "sparse_log.txt", "stage.json",
                        "sparse/cameras.bin", "sparse/images.txt", "sparse/points3D.bin"}) {
    EXPECT_TRUE(fs::exists(out / f)) << f;
  }
  EXPECT_FALSE(fs::exists(out / "work"));
  const geometry::SparseModel model = geometry::ReadModel((out / "sparse").string());
  for (const auto& [id, cam] : model.cameras) {
    EXPECT_EQ(cam.model, geometry::CameraModelId::kPinhole);
  }
  for (const auto& [id, image] : model.images) {
    EXPECT_TRUE(fs::exists(out / "images" / image.name)) << image.name;
  }
  EXPECT_EQ(ReadDepthRanges((out / "depth_ranges.json").string()).size(), model.images.size());
  ReadPanoramaFrame((out / "frame.json").string());
  return model;
}

TEST(SparseAccuracyTest, DefaultSyntheticPartialCapture) {
  const fs::path dir = TempDir("synthetic");
  synth::SynthOptions synth_options;  // The default partial capture (16 photos).
  synth_options.panorama_width = 64;  // Ground-truth panoramas are not used here.
  synth_options.write_master = false;
  synth::GenerateCapture(synth_options, (dir / "capture").string());
  const geometry::SparseModel truth = geometry::ReadModel((dir / "capture" / "sparse").string());
  ASSERT_FALSE(truth.cameras.empty());

  SparseStageOptions options = DefaultOptions();
  options.input_type = SparseInputType::kPhotos;
  // Rendered photos carry no EXIF: give the focal length a camera's EXIF would.
  options.import.focal_px = truth.cameras.begin()->second.FocalX();
  SparseStageResult result;
  const geometry::SparseModel model =
      RunAndRead((dir / "capture" / "images").string(), dir / "out", options, &result);
  const int n = static_cast<int>(truth.images.size());
  EXPECT_GE(result.num_registered, (9 * n + 9) / 10) << "registered " << result.num_registered;

  const PoseComparison c = ComparePoses(PosesOf(model), PosesOf(truth));
  const double rig_radius_m = 0.3;
  std::printf("synthetic: %d/%d registered, rotation max %.3f deg, centre mean %.5f max %.5f m\n",
              result.num_registered, n, c.max_rotation_error_deg, c.mean_centre_error,
              c.max_centre_error);
  EXPECT_LT(c.max_rotation_error_deg, 0.5);
  // Centre error: the mean over photos under 1% of the rig radius, and no
  // photo beyond 2% (the camera's position along its own optical axis is the
  // least constrained coordinate of an outward-looking rig).
  EXPECT_LT(c.mean_centre_error, 0.01 * rig_radius_m);
  EXPECT_LT(c.max_centre_error, 0.02 * rig_radius_m);

  // The frame: a partial capture whose up agrees with the truth's +Y.
  EXPECT_FALSE(result.frame.full_capture);
  EXPECT_LT(std::acos(std::min(1.0, (c.alignment.R * result.frame.up).dot(Eigen::Vector3d::UnitY()))) *
                180 / M_PI,
            2.0);
  fs::remove_all(dir);
}

TEST(SparseAccuracyTest, FernAgreesWithLlffPoses) {
  const std::string fern = DatasetDir("fern");
  if (fern.empty()) GTEST_SKIP() << "../shared/datasets/fern is absent; skipping";
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(fs::path(fern) / "images")) {
    names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  const auto reference = ReadLlffPosesBounds(fern + "/poses_bounds.npy", names);
  std::map<std::string, geometry::Pose> reference_poses;
  for (const auto& [name, cam] : reference) reference_poses[name] = cam.pose;

  const fs::path dir = TempDir("fern");
  SparseStageResult result;
  const geometry::SparseModel model =
      RunAndRead(fern + "/images", dir / "out", DefaultOptions(), &result);
  EXPECT_EQ(result.num_registered, 20);
  const PoseComparison c = ComparePoses(PosesOf(model), reference_poses);
  std::printf("fern: %d/20 registered, rotation max %.3f mean %.3f deg, centre max %.4f of spread\n",
              result.num_registered, c.max_rotation_error_deg, c.mean_rotation_error_deg,
              c.max_centre_error / c.reference_spread);
  EXPECT_EQ(c.num_common, 20);
  EXPECT_LT(c.max_rotation_error_deg, 1.0);
  EXPECT_LT(c.max_centre_error, 0.05 * c.reference_spread);
  fs::remove_all(dir);
}

TEST(SparseAccuracyTest, FountainAgreesWithGroundTruth) {
  const std::string fountain = DatasetDir("fountain-p11");
  if (fountain.empty()) GTEST_SKIP() << "../shared/datasets/fountain-p11 is absent; skipping";
  std::map<std::string, geometry::Pose> reference_poses;
  for (const auto& [name, cam] : ReadStrechaCameras(fountain + "/gt_dense_cameras")) {
    reference_poses[name] = cam.pose;
  }
  const fs::path dir = TempDir("fountain");
  SparseStageResult result;
  const geometry::SparseModel model =
      RunAndRead(fountain + "/images", dir / "out", DefaultOptions(), &result);
  EXPECT_EQ(result.num_registered, 11);
  const PoseComparison c = ComparePoses(PosesOf(model), reference_poses);
  std::printf("fountain-p11: %d/11 registered, rotation max %.3f deg, centre max %.4f of spread\n",
              result.num_registered, c.max_rotation_error_deg,
              c.max_centre_error / c.reference_spread);
  EXPECT_EQ(c.num_common, 11);
  EXPECT_LT(c.max_rotation_error_deg, 0.5);
  EXPECT_LT(c.max_centre_error, 0.01 * c.reference_spread);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace casual3d::sfm
