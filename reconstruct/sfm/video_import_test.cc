// Frame selection from videos: the picking rule on given measures, and a clip
// written by FFmpeg (skipped when ffmpeg is not installed).

#include "reconstruct/sfm/video_import.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace casual3d::sfm {
namespace {

namespace fs = std::filesystem;

TEST(PickFramesTest, SpreadOverTheMotionSharpAndBounded) {
  // 200 frames: moving 1 unit per frame, a pause (frames 50..149 still), moving again.
  const int n = 200;
  std::vector<double> sharpness(n, 100.0), motion(n, 1.0);
  for (int i = 50; i < 150; ++i) motion[i] = 0.0;
  for (int i = 20; i < 23; ++i) sharpness[i] = 20.0;  // Motion blur.
  sharpness[160] = 130.0;                             // The sharpest near 160.
  VideoFrameOptions options;
  options.max_frames = 11;
  int blurred = 0;
  const std::vector<int> picked = PickFrames(sharpness, motion, 0.0, options, &blurred);
  EXPECT_EQ(blurred, 3);
  ASSERT_EQ(picked.size(), 11u);  // Total motion 99 in 10 steps of 9.9.
  int in_pause = 0;
  for (size_t k = 0; k < picked.size(); ++k) {
    if (k) EXPECT_GT(picked[k], picked[k - 1]);
    EXPECT_TRUE(picked[k] < 20 || picked[k] > 22) << picked[k];
    in_pause += picked[k] > 50 && picked[k] < 150;
  }
  EXPECT_LE(in_pause, 1);  // The pause is one place, not a hundred frames.
  EXPECT_NE(std::set<int>(picked.begin(), picked.end()).count(160), 0u);
  // A floor on the step: 99 units at >= 30 per step give 4 frames.
  EXPECT_EQ(PickFrames(sharpness, motion, 30.0, options, nullptr).size(), 4u);
}

class VideoImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (std::system("ffmpeg -version >/dev/null 2>&1") != 0) GTEST_SKIP() << "ffmpeg not installed";
    root_ = fs::path(::testing::TempDir()) / ("video_import_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "png");
    fs::create_directories(root_ / "frames");
  }
  void TearDown() override { fs::remove_all(root_); }
  fs::path root_;
};

TEST_F(VideoImportTest, ClipFromFfmpegIsSampledUprightWithoutBlurredFrames) {
  // A window panning 4 px per frame over a random texture; frames 30..33 blurred.
  cv::Mat texture(240, 900, CV_8UC3);
  cv::theRNG().state = 7;
  cv::randu(texture, 0, 255);
  cv::GaussianBlur(texture, texture, {0, 0}, 1.5);
  const int n = 90;
  for (int i = 0; i < n; ++i) {
    cv::Mat frame = texture(cv::Rect(4 * i, 0, 320, 240)).clone();
    if (i >= 30 && i < 34) cv::blur(frame, frame, {15, 1});
    char name[32];
    std::snprintf(name, sizeof(name), "%03d.png", i);
    cv::imwrite((root_ / "png" / name).string(), frame);
  }
  // Encoded, then given a display rotation as phones record portrait clips.
  const std::string flat = (root_ / "flat.mp4").string();
  const std::string clip = (root_ / "clip.mp4").string();
  const std::string command = "ffmpeg -v error -y -framerate 30 -i " + (root_ / "png").string() +
                              "/%03d.png -c:v libx264 -crf 12 -pix_fmt yuv420p " + flat +
                              " && ffmpeg -v error -y -i " + flat +
                              " -c copy -metadata:s:v:0 rotate=90 " + clip + " && rm " + flat;
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  EXPECT_EQ(VideoOf(root_.string()), clip);  // The folder's one video (no photos beside it).
  EXPECT_EQ(VideoOf(clip), clip);
  EXPECT_EQ(VideoOf((root_ / "png").string()), "");  // A folder of photos.

  VideoFrameOptions options;
  options.max_frames = 12;
  const VideoFrames v = ExtractVideoFrames(clip, (root_ / "frames").string(), options);
  EXPECT_EQ(v.frames_decoded, n);
  EXPECT_NEAR(v.fps, 30.0, 0.01);
  EXPECT_EQ(std::abs(v.rotation_deg), 90);
  EXPECT_EQ(v.width, 240);  // Upright: the rotation metadata turns 320x240 into portrait.
  EXPECT_EQ(v.height, 320);
  EXPECT_GE(v.blurred, 3);
  // 89 * 4 px = 356 px of motion over a 400 px diagonal.
  EXPECT_NEAR(v.motion_diagonals, 356.0 / 400.0, 0.1);
  ASSERT_EQ(v.picked.size(), 12u);
  for (int f : v.picked) EXPECT_TRUE(f < 30 || f > 33) << "picked blurred frame " << f;
  EXPECT_LT(v.picked.front(), 5);
  EXPECT_GT(v.picked.back(), n - 6);
  // Written under their index in the clip.
  const cv::Mat first = cv::imread((root_ / "frames" / VideoFrameName(v.picked.front())).string());
  EXPECT_EQ(first.cols, 240);
  EXPECT_EQ(first.rows, 320);
  EXPECT_EQ(VideoFrameName(v.picked.back()), "frame_0000" + std::to_string(v.picked.back()) + ".jpg");
  EXPECT_EQ(std::distance(fs::directory_iterator(root_ / "frames"), fs::directory_iterator()), 12);
}

TEST_F(VideoImportTest, NotAVideoIsNamed) {
  const std::string fake = (root_ / "fake.mp4").string();
  std::ofstream(fake) << "not a video";
  try {
    ExtractVideoFrames(fake, (root_ / "frames").string(), {});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(fake + ": cannot decode the video"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace casual3d::sfm
