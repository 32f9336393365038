// End-to-end: Debian's COLMAP (CPU SIFT, exhaustive matching, incremental
// mapper) must register the default synthetic partial capture: at least 90% of
// the photos, each with a rotation error under 1 degree after a similarity
// alignment of the camera centres to the ground truth. This is what shows that
// the synthetic photos are realistic enough to drive the real pipeline.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/geometry/pose.h"
#include "reconstruct/synth/synth.h"

namespace casual3d {
namespace {

namespace fs = std::filesystem;

bool HaveColmap() { return std::system("command -v colmap >/dev/null 2>&1") == 0; }

// Runs a shell command with output to `log`; returns its exit status and time.
int RunLogged(const std::string& command, const std::string& log, double* seconds) {
  const auto start = std::chrono::steady_clock::now();
  const int status = std::system((command + " >" + log + " 2>&1").c_str());
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return status;
}

std::string Tail(const std::string& path, size_t max_chars = 3000) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string s = ss.str();
  return s.size() > max_chars ? s.substr(s.size() - max_chars) : s;
}

TEST(SynthColmapTest, ColmapRegistersTheDefaultPartialCapture) {
  if (!HaveColmap()) GTEST_SKIP() << "the colmap program is not installed (Debian package colmap)";
  const fs::path dir =
      fs::temp_directory_path() / ("casual3d_synth_colmap_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string capture = (dir / "capture").string();

  synth::SynthOptions options;  // The default partial capture.
  options.panorama_width = 256;  // The panorama is not used here.
  options.write_master = false;
  const synth::CaptureSummary summary = synth::GenerateCapture(options, capture);
  const geometry::SparseModel truth = geometry::ReadModel(capture + "/sparse");
  const geometry::Camera& cam = truth.cameras.at(1);

  char params[256];
  std::snprintf(params, sizeof(params), "%.6f,%.6f,%.6f,%.6f", cam.params[0], cam.params[1],
                cam.params[2], cam.params[3]);
  const std::string db = (dir / "database.db").string();
  const std::string out = (dir / "sparse").string();
  fs::create_directories(out);
  double t_extract = 0, t_match = 0, t_map = 0;
  const std::string log1 = (dir / "extract.log").string(), log2 = (dir / "match.log").string(),
                    log3 = (dir / "map.log").string();
  ASSERT_EQ(RunLogged("colmap feature_extractor --database_path " + db + " --image_path " + capture +
                    "/images --ImageReader.camera_model PINHOLE --ImageReader.single_camera 1"
                    " --ImageReader.camera_params " + params +
                    " --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads 2"
                    " --SiftExtraction.max_num_features 4096",
                log1, &t_extract),
            0)
      << Tail(log1);
  ASSERT_EQ(RunLogged("colmap exhaustive_matcher --database_path " + db +
                    " --SiftMatching.use_gpu 0 --SiftMatching.num_threads 2",
                log2, &t_match),
            0)
      << Tail(log2);
  ASSERT_EQ(RunLogged("colmap mapper --database_path " + db + " --image_path " + capture +
                    "/images --output_path " + out +
                    " --Mapper.num_threads 2 --Mapper.ba_refine_focal_length 0"
                    " --Mapper.ba_refine_principal_point 0 --Mapper.ba_refine_extra_params 0"
                    // A hand-held capture turns about a point: baselines are
                    // short (9-60 cm), so the default 16 degree minimum
                    // triangulation angle of the initial pair is never met.
                    " --Mapper.init_min_tri_angle 4",
                log3, &t_map),
            0)
      << Tail(log3);

  // The mapper may write several models (0, 1, ...): take the largest.
  geometry::SparseModel best;
  for (const auto& entry : fs::directory_iterator(out)) {
    if (!entry.is_directory()) continue;
    geometry::SparseModel m = geometry::ReadModel(entry.path().string());
    if (m.images.size() > best.images.size()) best = std::move(m);
  }
  const int n = static_cast<int>(truth.images.size());
  const int registered = static_cast<int>(best.images.size());

  // Align the reconstruction to the ground truth by the camera centres.
  std::vector<Eigen::Vector3d> src, dst;
  std::vector<std::pair<const geometry::ModelImage*, const geometry::ModelImage*>> pairs;
  for (const auto& [id, image] : best.images) {
    const geometry::ModelImage* gt = truth.FindImageByName(image.name);
    ASSERT_NE(gt, nullptr) << image.name;
    src.push_back(image.pose.Center());
    dst.push_back(gt->pose.Center());
    pairs.emplace_back(&image, gt);
  }
  geometry::Similarity3 sim;
  ASSERT_TRUE(geometry::EstimateSimilarity(src, dst, &sim)) << registered << " images registered";
  double max_rot_deg = 0, max_centre_m = 0;
  for (const auto& [est, gt] : pairs) {
    const geometry::Pose aligned = sim.ApplyToPose(est->pose);
    max_rot_deg = std::max(max_rot_deg, geometry::RotationAngleDeg(aligned.rotation, gt->pose.rotation));
    max_centre_m = std::max(max_centre_m, (aligned.Center() - gt->pose.Center()).norm());
  }
  std::printf(
      "colmap: %d/%d registered, %zu points; max rotation error %.3f deg, max centre error "
      "%.4f m; feature_extractor %.1f s, exhaustive_matcher %.1f s, mapper %.1f s (synth %.1f s)\n",
      registered, n, best.points.size(), max_rot_deg, max_centre_m, t_extract, t_match, t_map,
      summary.seconds_total);
  ::testing::Test::RecordProperty("registered", registered);
  ::testing::Test::RecordProperty("max_rotation_error_mdeg", static_cast<int>(1000 * max_rot_deg));

  EXPECT_GE(registered, static_cast<int>(std::ceil(0.9 * n)));
  EXPECT_LT(max_rot_deg, 1.0);
  // The rig's centres lie on a 0.3 m sphere: a correct registration puts them
  // within a few centimetres of the truth after alignment.
  EXPECT_LT(max_centre_m, 0.03);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace casual3d
