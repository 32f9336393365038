#include "reconstruct/pipeline/panorama_stage.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "encoder/master_file.h"
#include "reconstruct/io/exr_io.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/pipeline/ground_truth_eval.h"
#include "reconstruct/synth/synth.h"

namespace casual3d::pipeline {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("casual3d_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Runs the panorama stage on a small synthetic capture with its ground-truth
// depth maps and compares the front layer with the ground-truth panorama.
void CheckAgainstGroundTruth(synth::RigKind rig, int photos, double min_within_3pct,
                             double min_coverage, double min_back_near_edges) {
  const fs::path dir = TempDir(rig == synth::RigKind::kSphere ? "pano_sphere" : "pano_partial");
  synth::SynthOptions synth_options;
  synth_options.rig = rig;
  synth_options.width = 384;
  synth_options.num_photos = photos;
  synth_options.panorama_width = 1024;
  synth_options.write_master = false;
  synth::GenerateCapture(synth_options, dir.string());

  PanoramaStageOptions options;
  options.pano_width = 1024;
  options.stitch.solve_width = 256;
  options.stitch.solve_height = 128;
  PanoramaStageReport report;
  const TwoLayerPanorama pano =
      RunPanoramaStage(dir.string(), dir.string(), (dir / "panorama").string(), options, &report);
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  EXPECT_TRUE(fs::exists(dir / "panorama" / "master.exr"));
  EXPECT_TRUE(fs::exists(dir / "panorama" / "preview" / "front_color.png"));
  const auto reread = encoder::ReadMasterFile((dir / "panorama" / "master.exr").string());
  ASSERT_TRUE(reread.ok()) << reread.status().ToString();
  EXPECT_TRUE(*reread == pano);

  const ImageF gt = io::ReadExrChannels((dir / "ground_truth" / "panorama.exr").string(), {"front.Z"});
  ASSERT_EQ(gt.width(), 1024);
  long finite = 0, covered = 0, within = 0;
  for (int y = 0; y < 512; ++y) {
    for (int x = 0; x < 1024; ++x) {
      const float truth = gt.at(x, y);
      if (!std::isfinite(truth) || truth <= 0) continue;
      ++finite;
      if (!pano.present(kFront, x, y)) continue;
      ++covered;
      const float est = pano.layer(kFront).depth_m[pano.index(x, y)];
      within += std::abs(est - truth) <= 0.03f * truth;
    }
  }
  ASSERT_GT(covered, 0);
  const double frac = static_cast<double>(within) / covered;
  std::printf("front within 3%%: %.4f of %ld covered pixels (%.3f of finite ground truth)\n", frac,
              covered, static_cast<double>(covered) / finite);
  EXPECT_GE(frac, min_within_3pct);
  EXPECT_GE(static_cast<double>(covered) / finite, min_coverage);
  const GroundTruthComparison c =
      CompareWithGroundTruthFile(pano, (dir / "ground_truth" / "panorama.exr").string());
  EXPECT_EQ(c.front_covered, covered);
  EXPECT_EQ(c.front_within_3pct, within);
  std::printf("back behind %.4f of %ld edge pixels; links across edges %ld of %ld\n",
              c.BackNearEdges(), c.back_edge_pixels, c.edge_pairs_linked, c.edge_pairs);
  EXPECT_GE(c.BackNearEdges(), min_back_near_edges);
  EXPECT_LE(c.LinksAcrossEdges(), 0.01);
  // Issue 6: the front layer covers the photos' field of view with no hole
  // larger than 1% of it (with exact depth maps nearly all of it is covered).
  const CoverageStats& fov = report.front_fov;
  std::printf("field of view %.3f sr: %.4f covered, %d holes, largest %.5f (interior %.5f)\n",
              fov.fov_steradians, fov.covered_fraction, fov.num_holes, fov.largest_hole_fraction,
              fov.largest_interior_hole_fraction);
  EXPECT_GT(fov.fov_pixels, 0);
  EXPECT_GE(fov.covered_fraction, 0.99);
  EXPECT_LE(fov.largest_hole_fraction, 0.002);
  const CoverageStats& foot = report.front_footprint;
  std::printf("footprint %.3f sr: %.4f covered, %d holes, largest %.5f\n", foot.fov_steradians,
              foot.covered_fraction, foot.num_holes, foot.largest_hole_fraction);
  EXPECT_GE(foot.covered_fraction, 0.99);
  EXPECT_LE(foot.largest_hole_fraction, 0.002);
  fs::remove_all(dir);
}

TEST(PanoramaStageTest, PartialCaptureWithGroundTruthDepthMatchesGroundTruthPanorama) {
  CheckAgainstGroundTruth(synth::RigKind::kPartial, 16, 0.95, 0.05, 0.85);
}

TEST(PanoramaStageTest, SphereCaptureWithGroundTruthDepthMatchesGroundTruthPanorama) {
  // The sphere rig's two rings see latitudes up to about +-60 degrees: 70% of the sphere.
  CheckAgainstGroundTruth(synth::RigKind::kSphere, 50, 0.95, 0.70, 0.78);
}

// A 4-photo synthetic capture of 160-pixel photos in `dir`, and stage
// options for a 256-wide panorama of it.
PanoramaStageOptions SmallCapture(const fs::path& dir) {
  synth::SynthOptions synth_options;
  synth_options.width = 160;
  synth_options.num_photos = 4;
  synth_options.panorama_width = 128;
  synth_options.write_master = false;
  synth::GenerateCapture(synth_options, dir.string());
  PanoramaStageOptions options;
  options.pano_width = 256;
  options.stitch.solve_width = 128;
  options.stitch.solve_height = 64;
  return options;
}

TEST(PanoramaStageTest, MissingDepthMapIsAClearError) {
  const fs::path dir = TempDir("pano_missing");
  const PanoramaStageOptions options = SmallCapture(dir);
  fs::remove(dir / "depth" / "0001.exr");
  try {
    RunPanoramaStage(dir.string(), dir.string(), (dir / "out").string(), options);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("0001.exr: missing depth map"), std::string::npos)
        << e.what();
  }
  fs::remove_all(dir);
}

TEST(PanoramaStageTest, OfSeveralUnreadablePhotosTheFirstInModelOrderIsNamed) {
  const fs::path dir = TempDir("pano_unreadable");
  PanoramaStageOptions options = SmallCapture(dir);
  // Photos are read as they are warped, several at a time; the error must
  // not depend on which thread failed first.
  for (const char* name : {"0001.jpg", "0003.jpg"})
    io::WriteFileAtomic((dir / "images" / name).string(), "not a photo");
  options.num_threads = 4;
  for (int run = 0; run < 3; ++run) {
    try {
      RunPanoramaStage(dir.string(), dir.string(), (dir / "out").string(), options);
      FAIL() << "expected an error";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("0001.jpg"), std::string::npos) << e.what();
    }
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace casual3d::pipeline
