#include "reconstruct/synth/clip.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

#include "base/testing/scratch_dir.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/sfm/video_import.h"
#include "reconstruct/synth/default_scene.h"
#include "reconstruct/synth/synth.h"

namespace casual3d::synth {
namespace {

namespace fs = std::filesystem;

class ClipTest : public casual3d::testing::TestWithScratchDir {};

TEST(ClipPathTest, PassesThroughTheKeysSmoothly) {
  RigOptions rig_options;  // The default partial rig: 16 photos.
  const Rig rig = MakeRig(rig_options, DefaultRigCentre());
  const int frames = 301;  // 20 frames per interval between keys.
  std::vector<double> times;
  const std::vector<geometry::Pose> path = ClipPath(rig.poses, frames, &times);
  ASSERT_EQ(path.size(), 301u);
  ASSERT_EQ(times.size(), 301u);
  EXPECT_DOUBLE_EQ(times.front(), 0.0);
  EXPECT_DOUBLE_EQ(times.back(), 15.0);
  // Every 20th frame is a key.
  for (int k = 0; k < 16; ++k) {
    const geometry::Pose& p = path[20 * k];
    EXPECT_LT((p.Center() - rig.poses[k].Center()).norm(), 1e-9) << k;
    EXPECT_LT(geometry::RotationAngleDeg(p.rotation, rig.poses[k].rotation), 1e-6) << k;
  }
  // Smooth: no jumps between frames, and the step changes little from one
  // frame to the next (a C1 path at an even pace within each interval). The
  // grid's directions are 18 and 12 degrees apart, so a frame turns by
  // about 0.6 to 0.9 degrees here.
  double largest_turn = 0, largest_change = 0;
  for (int f = 1; f < frames; ++f) {
    const double turn = geometry::RotationAngleDeg(path[f].rotation, path[f - 1].rotation);
    largest_turn = std::max(largest_turn, turn);
    if (f >= 2) {
      const double before = geometry::RotationAngleDeg(path[f - 1].rotation, path[f - 2].rotation);
      largest_change = std::max(largest_change, std::abs(turn - before));
    }
  }
  EXPECT_LT(largest_turn, 1.5);
  EXPECT_LT(largest_change, 0.2);
}

TEST(ClipPathTest, FrameNamesAreTheVideoImports) {
  for (int i : {0, 7, 299, 123456}) EXPECT_EQ(ClipFrameName(i), sfm::VideoFrameName(i));
  EXPECT_EQ(ClipFrameName(42), "frame_000042.jpg");
}

TEST_F(ClipTest, CaptureWithAClipWritesFramesAndTheirGroundTruth) {
  SynthOptions o;
  o.width = 96;
  o.num_photos = 4;
  o.panorama_width = 64;
  o.write_master = false;
  o.video_frames = 10;
  const CaptureSummary s = GenerateCapture(o, scratch_.Path("cap"));
  EXPECT_EQ(s.video_frames, 10);
  const fs::path cap = scratch_.path() / "cap";
  for (int f = 0; f < 10; ++f) {
    const Image8 frame = io::ReadImage((cap / "video" / ClipFrameName(f)).string());
    EXPECT_EQ(frame.width(), 96);
    EXPECT_EQ(frame.height(), 72);
  }
  EXPECT_FALSE(fs::exists(cap / "video" / ClipFrameName(10)));

  // The ground truth holds the photos as the capture's model poses them, and
  // the frames, with the photos' camera.
  const geometry::SparseModel photos = geometry::ReadModel((cap / "sparse").string());
  const geometry::SparseModel truth = geometry::ReadModel((cap / "video" / "sparse").string());
  ASSERT_EQ(truth.images.size(), 14u);
  ASSERT_EQ(truth.cameras.size(), 1u);
  EXPECT_EQ(truth.cameras.begin()->second.params, photos.cameras.begin()->second.params);
  for (const auto& [id, image] : photos.images) {
    const geometry::ModelImage* same = truth.FindImageByName(image.name);
    ASSERT_NE(same, nullptr) << image.name;
    EXPECT_LT((same->pose.Center() - image.pose.Center()).norm(), 1e-9) << image.name;
  }
  // No frame is taken from a photo's pose (a second take of the sweep), but
  // the clip passes within a few centimetres of each photo.
  const nlohmann::json j = nlohmann::json::parse(io::ReadFile((cap / "capture.json").string()));
  ASSERT_EQ(j["video"]["nearest_frame"].size(), 4u);
  for (const auto& n : j["video"]["nearest_frame"]) {
    EXPECT_GT(n["distance_m"].get<double>(), 1e-4) << n;
    EXPECT_LT(n["distance_m"].get<double>(), 0.08) << n;
  }
  EXPECT_GT(s.video_min_distance_m, 1e-4);
  EXPECT_LT(s.video_max_distance_m, 0.08);
  // Without a clip the capture has no video folder.
  o.video_frames = 0;
  GenerateCapture(o, scratch_.Path("photos_only"));
  EXPECT_FALSE(fs::exists(scratch_.path() / "photos_only" / "video"));
}

TEST(ClipOptionsTest, VideoFramesAreChecked) {
  SynthOptions o;
  o.video_frames = 1;
  EXPECT_EQ(o.Check().message(), "video_frames 1 outside 0 or [2, 100000]");
  o.video_frames = 300;
  EXPECT_TRUE(o.Check().ok());
  o.rig = RigKind::kSphere;
  EXPECT_EQ(o.Check().message(),
            "video_frames 300: a video clip follows the partial or walk-around rig, not the "
            "sphere rig");
}

}  // namespace
}  // namespace casual3d::synth
