#include "reconstruct/synth/synth.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include <gtest/gtest.h>

#include "base/testing/scratch_dir.h"
#include "encoder/master_file.h"
#include "format/equirect.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/io/exr_io.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/synth/ground_truth_panorama.h"
#include "reconstruct/util/options_fields_testing.h"

namespace casual3d::synth {
namespace {

namespace fs = std::filesystem;

class SynthTest : public casual3d::testing::TestWithScratchDir {};

SynthOptions Small() {
  SynthOptions o;
  o.width = 320;
  o.height = 240;
  o.num_photos = 4;
  o.panorama_width = 256;
  o.sparse_step_px = 16;
  return o;
}

// Every file of a capture folder, relative path -> bytes.
std::map<std::string, std::string> Files(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = io::ReadFile(e.path().string());
  }
  return files;
}

TEST_F(SynthTest, SameSeedGivesSameBytesWhateverTheThreads) {
  SynthOptions a = Small();
  a.moving_object = true;
  a.num_threads = 1;
  SynthOptions b = a;
  b.num_threads = 2;
  GenerateCapture(a, scratch_.Path("a"));
  GenerateCapture(b, scratch_.Path("b"));
  const auto fa = Files(scratch_.Path("a")), fb = Files(scratch_.Path("b"));
  // 4 photos + 4 depth maps + 6 model files + panorama + master + capture.json.
  ASSERT_EQ(fa.size(), 17u);
  for (const char* name : {"images/0000.jpg", "images/0003.jpg", "depth/0000.exr",
                           "sparse/points3D.bin", "sparse/images.txt", "ground_truth/panorama.exr",
                           "ground_truth/master.exr", "capture.json"}) {
    ASSERT_EQ(fa.count(name), 1u) << name;
  }
  EXPECT_TRUE(fa == fb);
  for (const auto& [name, bytes] : fa) EXPECT_EQ(bytes, fb.at(name)) << name;
}

TEST_F(SynthTest, DifferentSeedGivesDifferentPhotos) {
  SynthOptions a = Small(), b = Small();
  b.seed = 2;
  GenerateCapture(a, scratch_.Path("a"));
  GenerateCapture(b, scratch_.Path("b"));
  for (const char* name : {"images/0000.jpg", "images/0002.jpg", "depth/0001.exr"}) {
    EXPECT_NE(io::ReadFile(scratch_.Path(std::string("a/") + name)), io::ReadFile(scratch_.Path(std::string("b/") + name)))
        << name;
  }
}

TEST_F(SynthTest, OptionsAreChecked) {
  SynthOptions o = Small();
  o.panorama_width = 1001;
  EXPECT_NE(o.Check().message().find("panorama_width"), std::string::npos);
  EXPECT_THROW(GenerateCapture(o, scratch_.Path("bad")), std::invalid_argument);
  EXPECT_FALSE(fs::exists(scratch_.Path("bad")));
  o = Small();
  o.noise_sigma = -1;
  EXPECT_NE(o.Check().message().find("noise_sigma"), std::string::npos);
  o = Small();
  o.num_photos = 1;
  EXPECT_NE(o.Check().message().find("num_photos"), std::string::npos);
  EXPECT_TRUE(Small().Check().ok());
}

TEST(SynthOptionsTest, EveryFieldIsDescribed) {
  util::testing::ExpectEveryFieldDescribed<SynthOptions>("SynthOptions");
}

double Median(std::vector<double> v) {
  if (v.empty()) return 1e9;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

double Bilinear(const Image8& img, double u, double v, int c) {
  const double x = u - 0.5, y = v - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  auto at = [&](int xx, int yy) {
    xx = std::clamp(xx, 0, img.width() - 1);
    yy = std::clamp(yy, 0, img.height() - 1);
    return static_cast<double>(img.at(xx, yy, c));
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

// Pixels lifted with their ground-truth depth and projected into another photo
// land on the same colour where visible; the panorama's depth agrees with the
// photos' depth; the sparse points agree with the depth maps.
TEST_F(SynthTest, GroundTruthIsConsistent) {
  SynthOptions o;
  o.width = 480;
  o.height = 360;
  o.num_photos = 6;
  o.noise_sigma = 0;
  o.exposure_jitter_stops = 0;
  o.panorama_width = 1024;
  o.sparse_step_px = 16;
  const std::string cap = scratch_.Path("cap");
  GenerateCapture(o, cap);
  const geometry::SparseModel model = geometry::ReadModel(cap + "/sparse");
  ASSERT_EQ(model.images.size(), 6u);
  const geometry::Camera& cam = model.cameras.at(1);
  std::vector<Image8> photos;
  std::vector<ImageF> depths;
  std::vector<geometry::Pose> poses;
  for (int i = 0; i < 6; ++i) {
    const geometry::ModelImage& im = model.images.at(i + 1);
    photos.push_back(io::ReadImage(cap + "/images/" + im.name));
    char name[32];
    std::snprintf(name, sizeof(name), "/depth/%04d.exr", i);
    depths.push_back(io::ReadExrChannels(cap + name, {"Z"}));
    poses.push_back(im.pose);
  }
  ASSERT_EQ(depths[0].width(), 480);

  // 1. Photo-to-photo colour consistency, and the same with a 1-pixel error
  // (which a convention bug such as a half-pixel or axis flip would exceed).
  std::vector<double> diffs, shifted_diffs;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      if (i == j) continue;
      for (int y = 2; y < cam.height - 2; y += 5) {
        for (int x = 2; x < cam.width - 2; x += 5) {
          const float z = depths[i].at(x, y);
          if (!std::isfinite(z)) continue;
          const Eigen::Vector3d ray = cam.Unproject(Eigen::Vector2d(x + 0.5, y + 0.5));
          const Eigen::Vector3d world = poses[i].CameraToWorld(ray * z);
          const Eigen::Vector3d pj = poses[j].WorldToCamera(world);
          if (pj.z() <= 0) continue;
          const Eigen::Vector2d uv = cam.Project(pj);
          if (uv.x() < 2 || uv.y() < 2 || uv.x() > cam.width - 2 || uv.y() > cam.height - 2) continue;
          // Visible in j: j's depth at that pixel (and its neighbours) agrees.
          const int xj = static_cast<int>(uv.x()), yj = static_cast<int>(uv.y());
          bool visible = true;
          for (int dy = -1; dy <= 1 && visible; ++dy)
            for (int dx = -1; dx <= 1 && visible; ++dx) {
              const float zj = depths[j].at(xj + dx, yj + dy);
              visible = std::isfinite(zj) && std::abs(zj - pj.z()) < 0.01 * pj.z();
            }
          if (!visible) continue;
          // Only textured pixels (local contrast >= 12 code values) tell a
          // correct reprojection from a shifted one.
          int lo = 255, hi = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              lo = std::min<int>(lo, photos[i].at(x + dx, y + dy, 1));
              hi = std::max<int>(hi, photos[i].at(x + dx, y + dy, 1));
            }
          if (hi - lo < 12) continue;
          double d = 0, ds = 0;
          for (int c = 0; c < 3; ++c) {
            const double src = photos[i].at(x, y, c);
            d += std::abs(Bilinear(photos[j], uv.x(), uv.y(), c) - src);
            ds += std::abs(Bilinear(photos[j], uv.x() + 1.0, uv.y(), c) - src);
          }
          diffs.push_back(d / 3);
          shifted_diffs.push_back(ds / 3);
        }
      }
    }
  }
  ASSERT_GT(diffs.size(), 3000u);
  const double median = Median(diffs), median_shifted = Median(shifted_diffs);
  std::vector<double> sorted = diffs;
  std::sort(sorted.begin(), sorted.end());
  const double p90 = sorted[sorted.size() * 9 / 10];
  std::printf("reprojection colour: %zu samples, median %.2f, p90 %.2f (1 px shifted: median %.2f)\n",
              diffs.size(), median, p90, median_shifted);
  // Measured: median 3.1, p90 9.3 (JPEG and bilinear resampling of textured
  // pixels), 1-pixel shift 5.0; a half-pixel error gives about 4.1.
  EXPECT_LT(median, 4.0);
  EXPECT_LT(p90, 12.0);
  EXPECT_LT(median, 0.72 * median_shifted);

  // 2. The ground-truth panorama's front depth matches the photos' depth for
  // the same 3D point (where the rig centre sees it too).
  const ImageF pano = io::ReadExrChannels(cap + "/ground_truth/panorama.exr", {"front.Z"});
  const Eigen::Vector3d centre(0, 1.5, 0);
  std::vector<double> rel;
  for (int y = 1; y < cam.height; y += 7) {
    for (int x = 1; x < cam.width; x += 7) {
      const float z = depths[0].at(x, y);
      if (!std::isfinite(z)) continue;
      const Eigen::Vector3d ray = cam.Unproject(Eigen::Vector2d(x + 0.5, y + 0.5));
      const Eigen::Vector3d d = poses[0].CameraToWorld(ray * z) - centre;
      double u, v;
      DirectionToEquirectPixel({d.x(), d.y(), d.z()}, pano.width(), pano.height(), &u, &v);
      const float pz = pano.at(WrapColumn(static_cast<int>(u), pano.width()),
                               std::min(static_cast<int>(v), pano.height() - 1));
      rel.push_back(std::isfinite(pz) ? std::abs(pz - d.norm()) / d.norm() : 1.0);
    }
  }
  const size_t agree = std::count_if(rel.begin(), rel.end(), [](double r) { return r < 0.02; });
  std::printf("panorama vs photo depth: %zu samples, %.1f%% within 2%%, median %.4f\n", rel.size(),
              100.0 * agree / rel.size(), Median(rel));
  EXPECT_GT(static_cast<double>(agree) / rel.size(), 0.9);
  EXPECT_LT(Median(rel), 0.003);

  // 3. Sparse points: observations lie on the depth maps.
  size_t obs = 0, on_surface = 0;
  for (const auto& [id, p] : model.points) {
    for (const geometry::TrackElement& t : p.track) {
      const geometry::ModelImage& im = model.images.at(t.image_id);
      const Eigen::Vector2d xy = im.points2d.at(t.point2d_idx).xy;
      EXPECT_EQ(im.points2d.at(t.point2d_idx).point3d_id, id);
      const double zc = im.pose.WorldToCamera(p.xyz).z();
      EXPECT_LT((cam.Project(im.pose.WorldToCamera(p.xyz)) - xy).norm(), 1e-6);
      const float zd = depths[t.image_id - 1].at(static_cast<int>(xy.x()), static_cast<int>(xy.y()));
      ++obs;
      on_surface += std::isfinite(zd) && std::abs(zd - zc) < 0.02 * zc;
    }
  }
  std::printf("sparse: %zu points, %zu observations, %.1f%% on the depth maps\n",
              model.points.size(), obs, 100.0 * on_surface / obs);
  EXPECT_GT(model.points.size(), 1000u);
  EXPECT_GT(static_cast<double>(on_surface) / obs, 0.95);

  // 4. The master file reads back as a valid two-layer panorama.
  const StatusOr<TwoLayerPanorama> master = encoder::ReadMasterFile(cap + "/ground_truth/master.exr");
  ASSERT_TRUE(master.ok()) << master.status().ToString();
  EXPECT_EQ(master->width(), 1024);
  EXPECT_EQ(master->height(), 512);
  EXPECT_DOUBLE_EQ(master->frame().centre[1], 1.5);
}

}  // namespace
}  // namespace casual3d::synth
