// End to end: a synthetic capture's photos -> `reconstruct` (COLMAP sparse,
// dense, panorama, encode) -> web package -> decode -> mesh -> render from
// every photo's pose -> compare with the photo (virtual rephotography), and
// the stage cache: a rerun does nothing, a stale stage reruns from there on.

#include <sys/types.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "encoder/gltf_export.h"
#include "encoder/master_file.h"
#include "encoder/webp_codec.h"
#include "format/file_source.h"
#include "format/mesh_builder.h"
#include "format/package_reader.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/pipeline/pipeline.h"
#include "reconstruct/render/photo_renderer.h"
#include "reconstruct/synth/synth.h"

namespace casual3d {
namespace {

namespace fs = std::filesystem;

bool HaveColmap() { return std::system("command -v colmap >/dev/null 2>&1") == 0; }

TEST(ReconstructEndToEndTest, PhotosToWebPackageAndBack) {
  if (!HaveColmap()) GTEST_SKIP() << "colmap is not installed (apt-get install colmap)";
  const fs::path dir = fs::temp_directory_path() / ("casual3d_e2e_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  synth::SynthOptions synth_options;
  synth_options.width = 640;
  synth_options.panorama_width = 256;
  synth_options.write_master = false;
  synth::GenerateCapture(synth_options, (dir / "capture").string());

  pipeline::PipelineOptions options;
  options.sparse.import.working_megapixels = 0.31;  // Keeps the 640x480 photos as they are.
  options.panorama.pano_width = 1024;
  options.panorama.stitch.solve_width = 256;
  options.panorama.stitch.solve_height = 128;
  options.tile_size = 256;
  const fs::path out = dir / "photo";
  const pipeline::PipelineReport report =
      pipeline::RunPipeline((dir / "capture" / "images").string(), out.string(), options);
  ASSERT_EQ(report.stages.size(), 4u);
  for (const pipeline::StageRun& run : report.stages) EXPECT_TRUE(run.ran) << run.stage;
  for (const char* f : {"web/manifest.json", "photo.c3d", "master.exr", "report.json",
                        "preview/front_color.png"}) {
    EXPECT_TRUE(fs::exists(out / f)) << f;
  }

  // The package decodes to the master file's panorama up to its quantization.
  const auto master = encoder::ReadMasterFile((out / "master.exr").string());
  ASSERT_TRUE(master.ok()) << master.status().ToString();
  FolderFileSource source((out / "web").string());
  encoder::WebpImageDecoder decoder;
  Manifest manifest;
  const auto pano = ReadPackage(source, decoder, ReadOptions(), &manifest);
  ASSERT_TRUE(pano.ok()) << pano.status().ToString();
  // Depth within the bound the package declares (spec Sec. 4.2), with float slack.
  const double depth_bound = manifest.depth.MaxRelativeError() + 1e-5;
  ASSERT_LT(depth_bound, 0.01);
  ASSERT_TRUE(pano->Validate().ok());
  ASSERT_EQ(pano->width(), 1024);
  long front = 0, depth_ok = 0;
  for (size_t i = 0; i < pano->layer(kFront).present.size(); ++i) {
    ASSERT_EQ(pano->layer(kFront).present[i], master->layer(kFront).present[i]);
    ASSERT_EQ(pano->layer(kFront).links[i], master->layer(kFront).links[i]);
    if (!pano->layer(kFront).present[i]) continue;
    ++front;
    const float a = pano->layer(kFront).depth_m[i], b = master->layer(kFront).depth_m[i];
    depth_ok += std::abs(a - b) <= depth_bound * b;
  }
  ASSERT_GT(front, 0);
  EXPECT_EQ(depth_ok, front);

  // Virtual rephotography from every registered photo's pose.
  const auto mesh = BuildMesh(*pano);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  const Image8 atlas = encoder::BuildColorAtlas(*pano);
  const fs::path sparse = out / "work" / "sparse";
  const geometry::SparseModel model = geometry::ReadModel((sparse / "sparse").string());
  ASSERT_GE(model.images.size(), 15u);
  double psnr_sum = 0, coverage_sum = 0;
  for (const auto& [id, image] : model.images) {
    const geometry::Camera& camera = model.cameras.at(image.camera_id);
    const render::RenderResult r =
        render::RenderPhotoView(*mesh, atlas.view(), pano->frame(), camera, image.pose);
    const Image8 photo = io::ReadImage((sparse / "images" / image.name).string());
    ASSERT_EQ(photo.width(), r.color.width());
    double se = 0;
    long n = 0;
    for (int y = 0; y < photo.height(); ++y) {
      for (int x = 0; x < photo.width(); ++x) {
        if (!r.mask.at(x, y)) continue;
        ++n;
        for (int c = 0; c < 3; ++c) {
          const double e = static_cast<double>(r.color.at(x, y, c)) - photo.at(x, y, c);
          se += e * e;
        }
      }
    }
    const double coverage = static_cast<double>(n) / (photo.width() * photo.height());
    const double psnr = 10 * std::log10(255.0 * 255.0 / (se / (3.0 * std::max<long>(n, 1))));
    psnr_sum += psnr;
    coverage_sum += coverage;
  }
  const double mean_psnr = psnr_sum / model.images.size();
  const double mean_coverage = coverage_sum / model.images.size();
  std::printf("rephotography of %zu photos: mean PSNR %.2f dB, mean coverage %.3f\n",
              model.images.size(), mean_psnr, mean_coverage);
  // Measured 25.6 dB and 0.988 (2026-12-06); these bounds catch a broken
  // stage, not a weak one.
  EXPECT_GT(mean_coverage, 0.85);
  EXPECT_GT(mean_psnr, 16.0);

  // Rerun: everything is cached.
  const pipeline::PipelineReport again =
      pipeline::RunPipeline((dir / "capture" / "images").string(), out.string(), options);
  for (const pipeline::StageRun& run : again.stages) EXPECT_FALSE(run.ran) << run.stage;
  // A changed panorama option makes the panorama and encode stages stale only.
  options.panorama.back_layer = false;
  const pipeline::PipelineReport front_only =
      pipeline::RunPipeline((dir / "capture" / "images").string(), out.string(), options);
  ASSERT_EQ(front_only.stages.size(), 4u);
  EXPECT_FALSE(front_only.stages[0].ran);
  EXPECT_FALSE(front_only.stages[1].ran);
  EXPECT_TRUE(front_only.stages[2].ran);
  EXPECT_TRUE(front_only.stages[3].ran);
  fs::remove_all(dir);
}

TEST(ReconstructEndToEndTest, ClearErrorsForBadInputs) {
  const fs::path dir = fs::temp_directory_path() / ("casual3d_e2e_bad_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "photos");
  pipeline::PipelineOptions options;
  // Not a folder.
  EXPECT_THROW(pipeline::RunPipeline((dir / "missing").string(), (dir / "out").string(), options),
               std::runtime_error);
  // --from a stage whose inputs were never computed.
  options.from = pipeline::Stage::kPanorama;
  try {
    pipeline::RunPipeline((dir / "photos").string(), (dir / "out").string(), options);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("has no current output"), std::string::npos) << e.what();
  }
  // --from after --to.
  options.to = pipeline::Stage::kDense;
  EXPECT_THROW(pipeline::RunPipeline((dir / "photos").string(), (dir / "out").string(), options),
               std::invalid_argument);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace casual3d
