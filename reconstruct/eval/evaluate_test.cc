#include "reconstruct/eval/evaluate.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "encoder/master_file.h"
#include "encoder/package_writer.h"
#include "reconstruct/eval/report.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/pipeline/panorama_stage.h"
#include "reconstruct/synth/synth.h"
#include "reconstruct/util/options_fields_testing.h"

namespace casual3d::eval {
namespace {

namespace fs = std::filesystem;

TEST(SelectPhotosTest, ExplicitNamesAndIndices) {
  const std::vector<std::string> names = {"a.jpg", "b.jpg", "c.jpg", "d.jpg"};
  EXPECT_EQ(SelectPhotos(names, {"c.jpg", "0", "c.jpg"}, 0, {}), (std::vector<int>{0, 2}));
  EXPECT_THROW(SelectPhotos(names, {"e.jpg"}, 0, {}), std::runtime_error);
  EXPECT_THROW(SelectPhotos(names, {"4"}, 0, {}), std::runtime_error);
}

TEST(SelectPhotosTest, EveryNthFollowsTheLlffProtocol) {
  std::vector<std::string> names;
  for (int i = 0; i < 20; ++i) names.push_back("IMG_" + std::to_string(100 + i) + ".JPG");
  EXPECT_EQ(SelectPhotos(names, {}, 8, {}), (std::vector<int>{0, 8, 16}));
  // Explicit photos win over the rule.
  EXPECT_EQ(SelectPhotos(names, {"3"}, 8, {}), (std::vector<int>{3}));
}

TEST(SelectPhotosTest, HeldOutListOrAll) {
  const std::vector<std::string> names = {"a.jpg", "b.jpg", "c.jpg"};
  EXPECT_EQ(SelectPhotos(names, {}, 0, {"c.jpg", "zz.jpg"}), (std::vector<int>{2}));
  EXPECT_EQ(SelectPhotos(names, {}, 0, {}), (std::vector<int>{0, 1, 2}));
}

TEST(EvaluateOptionsTest, CheckNamesTheField) {
  EvaluateOptions options;
  EXPECT_TRUE(options.Check().ok());
  options.width = 5;
  EXPECT_NE(options.Check().message().find("width"), std::string::npos);
  options.width = 900;
  options.metrics.psnr_cap_db = -1;
  EXPECT_NE(options.Check().message().find("metrics.psnr_cap_db"), std::string::npos);
  options.metrics.psnr_cap_db = 100;
  options.viewer.width = 8;
  EXPECT_EQ(options.Check().message(), "viewer.width 8 outside [16, 4096]");
}

TEST(EvaluateOptionsTest, EveryFieldButThePhotoListIsDescribed) {
  util::testing::ExpectEveryFieldDescribed<RephotoMetricOptions>("metrics");
  util::testing::ExpectEveryFieldDescribed<ViewerViewsOptions>("viewer");
  // `photos` is a list, which options_fields.h does not describe.
  EXPECT_EQ(util::DescribedFieldCount<EvaluateOptions>() + 1,
            util::AggregateFieldCount<EvaluateOptions>());
}

// End to end on a tiny synthetic capture: the 3D photo is built by the
// panorama stage from the capture's ground-truth depth maps (no COLMAP), then
// rephotographed from the capture's own poses and compared with its photos and
// ground-truth depth.
class EvaluateSyntheticTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("casual3d_eval_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    synth::SynthOptions synth_options;
    synth_options.width = 320;
    synth_options.num_photos = 8;
    synth_options.panorama_width = 512;
    synth_options.write_master = false;
    synth::GenerateCapture(synth_options, dir_.string());
    pipeline::PanoramaStageOptions pano;
    pano.pano_width = 1024;
    pano.stitch.solve_width = 256;
    pano.stitch.solve_height = 128;
    pano.write_previews = false;
    pipeline::RunPanoramaStage(dir_.string(), dir_.string(), (dir_ / "photo3d").string(), pano);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static fs::path dir_;
};
fs::path EvaluateSyntheticTest::dir_;

TEST_F(EvaluateSyntheticTest, RephotographsMatchThePhotosAndTheGroundTruthDepth) {
  EvaluateOptions options;
  options.width = 240;
  const PhotoModelEvaluation e =
      EvaluatePhoto3d(dir_.string(), (dir_ / "photo3d").string(), options);
  ASSERT_EQ(e.photos.size(), 8u);
  EXPECT_EQ(e.pano_width, 1024);
  EXPECT_GT(e.mesh_triangles, 100000u);
  EXPECT_FALSE(e.stage_seconds.empty());  // From panorama.json.
  for (const PhotoEvaluation& p : e.photos) {
    std::printf(
        "%s: completeness %.3f error %.4f (plain %.4f) PSNR %.2f SSIM %.3f depth median %.4f "
        "within 3%% %.3f\n",
        p.name.c_str(), p.metrics.completeness, p.metrics.error, p.metrics.error_plain,
        p.metrics.psnr_db, p.metrics.ssim, p.depth.median_relative_error, p.depth.within_tolerance);
    EXPECT_EQ(p.metrics.width, 240);
    EXPECT_EQ(p.metrics.height, 180);
    EXPECT_GT(p.metrics.completeness, 0.95) << p.name;
    EXPECT_LT(p.metrics.error, 0.04) << p.name;
    EXPECT_LT(p.metrics.error, p.metrics.error_plain) << p.name;
    EXPECT_GT(p.metrics.psnr_db, 22.0) << p.name;
    EXPECT_GT(p.metrics.ssim, 0.6) << p.name;
    ASSERT_TRUE(p.depth.available) << p.name;
    EXPECT_LT(p.depth.median_relative_error, 0.01) << p.name;
    EXPECT_NEAR(p.depth.median_ratio, 1.0, 0.01) << p.name;
    // Depth edges: the 240-px rendering and the 320-px ground truth sample
    // different points near them.
    EXPECT_GT(p.depth.within_tolerance, 0.85) << p.name;
  }
  EXPECT_TRUE(e.has_depth);
  EXPECT_GT(e.mean_depth_within, 0.9);
  EXPECT_LT(e.mean_error, 0.015);
  EXPECT_GT(e.mean_psnr_db, 25.0);
  EXPECT_GT(e.mean_completeness, 0.98);

  const std::string html = RenderHtmlReport(dir_.string(), {e});
  EXPECT_NE(html.find("<td class=\"l\">0007.jpg</td>"), std::string::npos);
}

// A 3D photo reconstructed with its own model has that model's scale: here
// the whole world (poses, panorama frame and depths) is 2.5 times larger than
// the capture's, and the depth comparison must undo it.
TEST_F(EvaluateSyntheticTest, DepthOfAModelAtAnotherScaleIsComparedAfterScaling) {
  constexpr double kScale = 2.5;
  const fs::path root = dir_ / "scaled";
  fs::create_directories(root / "work" / "sparse" / "sparse");
  geometry::SparseModel model = geometry::ReadModel((dir_ / "sparse").string());
  for (auto& [id, image] : model.images) image.pose.translation *= kScale;
  for (auto& [id, point] : model.points) point.xyz *= kScale;
  geometry::WriteModelBinary(model, (root / "work" / "sparse" / "sparse").string());
  auto pano = encoder::ReadMasterFile((dir_ / "photo3d" / "master.exr").string());
  ASSERT_TRUE(pano.ok()) << pano.status().ToString();
  for (int l = 0; l < kNumLayers; ++l)
    for (float& d : pano->layer(l).depth_m) d *= static_cast<float>(kScale);
  for (double& c : pano->frame().centre) c *= kScale;
  ASSERT_TRUE(encoder::WriteMasterFile(*pano, (root / "master.exr").string()).ok());

  EvaluateOptions options;
  options.width = 160;
  options.photos = {"0", "5"};
  const PhotoModelEvaluation e = EvaluatePhoto3d(dir_.string(), root.string(), options);
  EXPECT_NEAR(e.depth_scale, 1.0 / kScale, 1e-6);
  ASSERT_TRUE(e.has_depth);
  for (const PhotoEvaluation& p : e.photos) {
    EXPECT_GT(p.metrics.completeness, 0.95) << p.name;
    EXPECT_LT(p.depth.median_relative_error, 0.01) << p.name;
    EXPECT_NEAR(p.depth.median_ratio, 1.0, 0.01) << p.name;
  }
  fs::remove_all(root);
}

// A 3D photo whose own model lacks the evaluated photos (as one made from a
// video's frames lacks the photos held out of it): their poses come from the
// capture's ground truth, aligned to the 3D photo's model (here the whole
// world at 2.5 times the scale and shifted) by the photos both hold.
TEST_F(EvaluateSyntheticTest, PhotosMissingFromTheModelArePosedFromTheReference) {
  constexpr double kScale = 2.5;
  const Eigen::Vector3d shift(0.4, -1.0, 3.0);
  const fs::path root = dir_ / "without_0_and_5";
  fs::create_directories(root / "work" / "sparse" / "sparse");
  geometry::SparseModel model = geometry::ReadModel((dir_ / "sparse").string());
  for (int id : {1, 6}) model.images.erase(id);  // 0000.jpg and 0005.jpg.
  for (auto& [id, image] : model.images)
    image.pose = geometry::Pose::FromCenter(image.pose.R(), kScale * image.pose.Center() + shift);
  model.points.clear();
  for (auto& [id, image] : model.images) image.points2d.clear();
  geometry::WriteModelBinary(model, (root / "work" / "sparse" / "sparse").string());
  auto pano = encoder::ReadMasterFile((dir_ / "photo3d" / "master.exr").string());
  ASSERT_TRUE(pano.ok()) << pano.status().ToString();
  for (int l = 0; l < kNumLayers; ++l)
    for (float& d : pano->layer(l).depth_m) d *= static_cast<float>(kScale);
  for (int k = 0; k < 3; ++k) pano->frame().centre[k] = kScale * pano->frame().centre[k] + shift[k];
  ASSERT_TRUE(encoder::WriteMasterFile(*pano, (root / "master.exr").string()).ok());

  EvaluateOptions options;
  options.width = 160;
  options.viewer_views = false;
  options.photos = {"0000.jpg", "0005.jpg"};
  // Without the reference, the photos are not in the 3D photo's model.
  EXPECT_THROW(EvaluatePhoto3d(dir_.string(), root.string(), options), std::runtime_error);
  options.reference_poses = (dir_ / "sparse").string();
  const PhotoModelEvaluation e = EvaluatePhoto3d(dir_.string(), root.string(), options);
  ASSERT_TRUE(e.reference_alignment.has_value());
  EXPECT_EQ(e.reference_alignment->num_common, 6);
  EXPECT_NEAR(e.reference_alignment->model_to_reference.scale, 1.0 / kScale, 1e-6);
  EXPECT_NEAR(e.depth_scale, 1.0 / kScale, 1e-6);
  ASSERT_EQ(e.photos.size(), 2u);
  ASSERT_TRUE(e.has_depth);
  // As well rephotographed as from the capture's own poses.
  options.reference_poses.clear();
  const PhotoModelEvaluation direct =
      EvaluatePhoto3d(dir_.string(), (dir_ / "photo3d").string(), options);
  for (size_t i = 0; i < e.photos.size(); ++i) {
    const PhotoEvaluation& p = e.photos[i];
    EXPECT_GT(p.metrics.completeness, 0.95) << p.name;
    EXPECT_NEAR(p.metrics.psnr_db, direct.photos[i].metrics.psnr_db, 0.05) << p.name;
    EXPECT_LT(p.depth.median_relative_error, 0.01) << p.name;
    EXPECT_NEAR(p.depth.median_ratio, 1.0, 0.01) << p.name;
  }
  fs::remove_all(root);
}

TEST_F(EvaluateSyntheticTest, ReadsSingleFilePackages) {
  auto pano = encoder::ReadMasterFile((dir_ / "photo3d" / "master.exr").string());
  ASSERT_TRUE(pano.ok()) << pano.status().ToString();
  encoder::PackageOptions package;
  package.tile_size = 256;
  auto files = encoder::EncodePackage(*pano, package);
  ASSERT_TRUE(files.ok()) << files.status().ToString();
  const fs::path c3d = dir_ / "packaged" / "photo.c3d";
  fs::create_directories(c3d.parent_path());
  ASSERT_TRUE(encoder::WritePackageSingleFile(*files, c3d.string()).ok());

  EvaluateOptions options;
  options.width = 160;
  options.photos = {"2"};
  const PhotoModelEvaluation master =
      EvaluatePhoto3d(dir_.string(), (dir_ / "photo3d").string(), options);
  const PhotoModelEvaluation packaged = EvaluatePhoto3d(dir_.string(), c3d.string(), options);
  ASSERT_EQ(packaged.photos.size(), 1u);
  EXPECT_EQ(packaged.package_bytes, fs::file_size(c3d));
  const RephotoMetrics& a = master.photos[0].metrics;
  const RephotoMetrics& b = packaged.photos[0].metrics;
  std::printf("master: error %.4f PSNR %.2f; package: error %.4f PSNR %.2f\n", a.error, a.psnr_db,
              b.error, b.psnr_db);
  // Lossy colour and quantized depth change the figures only a little.
  EXPECT_NEAR(b.completeness, a.completeness, 0.01);
  EXPECT_NEAR(b.error, a.error, 0.005);
  EXPECT_NEAR(b.psnr_db, a.psnr_db, 1.5);
}

TEST_F(EvaluateSyntheticTest, EvaluatesTheHeldOutPhotosListedByTheReport) {
  {
    std::ofstream report(dir_ / "photo3d" / "report.json");
    report << R"({"holdout": ["0003.jpg"], "stages": [{"stage": "sparse", "seconds": 1.5}]})";
  }
  EvaluateOptions options;
  options.width = 160;
  const PhotoModelEvaluation e =
      EvaluatePhoto3d(dir_.string(), (dir_ / "photo3d").string(), options);
  ASSERT_EQ(e.photos.size(), 1u);
  EXPECT_EQ(e.photos[0].name, "0003.jpg");
  EXPECT_TRUE(e.photos[0].held_out);
  ASSERT_EQ(e.stage_seconds.size(), 1u);
  EXPECT_EQ(e.stage_seconds[0].first, "sparse");

  options.photos = {"0", "0005.jpg"};
  const PhotoModelEvaluation chosen =
      EvaluatePhoto3d(dir_.string(), (dir_ / "photo3d").string(), options);
  ASSERT_EQ(chosen.photos.size(), 2u);
  EXPECT_EQ(chosen.photos[0].name, "0000.jpg");
  EXPECT_EQ(chosen.photos[1].name, "0005.jpg");
  EXPECT_FALSE(chosen.photos[1].held_out);
  fs::remove(dir_ / "photo3d" / "report.json");
}

TEST_F(EvaluateSyntheticTest, MissingInputsGiveOneClearError) {
  EvaluateOptions options;
  try {
    EvaluatePhoto3d(dir_.string(), (dir_ / "nope").string(), options);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nope: no such 3D photo"), std::string::npos) << e.what();
  }
  options.photos = {"missing.jpg"};
  EXPECT_THROW(EvaluatePhoto3d(dir_.string(), (dir_ / "photo3d").string(), options),
               std::runtime_error);
  // A capture folder without poses, and no work/sparse next to the 3D photo.
  const fs::path empty = dir_ / "empty_capture";
  fs::create_directories(empty);
  options.photos.clear();
  try {
    EvaluatePhoto3d(empty.string(), (dir_ / "photo3d").string(), options);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no camera poses"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace casual3d::eval
