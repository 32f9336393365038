// Failure handling of the sparse stage, with small generated photos and a
// stand-in `colmap` program; no real COLMAP run (see sparse_accuracy_test.cc).

#include "reconstruct/sfm/sparse_stage.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

namespace casual3d::sfm {
namespace {

namespace fs = std::filesystem;

class SparseStageTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::path(::testing::TempDir()) /
            ("sparse_stage_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_ / "photos");
    out_ = (root_ / "out").string();
    options_.colmap_path = FakeColmap("exit 0");
    // The stand-in writes no database; the descriptor matching that reads
    // it has its own test below.
    options_.native_matching = false;
  }
  void TearDown() override { fs::remove_all(root_); }

  void WritePhotos(int n, int width = 320, int height = 240) {
    std::mt19937 rng(5);
    for (int i = 0; i < n; ++i) {
      cv::Mat img(height, width, CV_8UC3);
      cv::randu(img, 0, 255);
      cv::imwrite((root_ / "photos" / ("p" + std::to_string(i) + ".jpg")).string(), img);
    }
  }
  std::string FakeColmap(const std::string& body) {
    const fs::path path = root_ / "colmap";
    std::ofstream(path) << "#!/bin/sh\n" << body << "\n";
    ::chmod(path.c_str(), 0755);
    return path.string();
  }
  // Runs the stage expecting a failure whose message contains every needle,
  // and checks that nothing was left at the output.
  void ExpectFailure(const std::vector<std::string>& needles) {
    try {
      RunSparseStage((root_ / "photos").string(), out_, options_);
      ADD_FAILURE() << "no error";
    } catch (const std::exception& e) {
      for (const auto& n : needles) {
        EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what();
      }
    }
    EXPECT_FALSE(fs::exists(out_));
    for (const auto& entry : fs::directory_iterator(root_)) {
      EXPECT_EQ(entry.path().filename().string().find("out.tmp-"), std::string::npos)
          << "staging folder left behind: " << entry.path();
    }
  }

  fs::path root_;
  std::string out_;
  SparseStageOptions options_;
};

TEST_F(SparseStageTest, TooFewPhotos) {
  WritePhotos(2);
  ExpectFailure({"found 2 photos", "at least 3"});
}

TEST_F(SparseStageTest, CorruptPhotoIsNamed) {
  WritePhotos(4);
  std::ofstream(root_ / "photos" / "broken.jpg") << "not a jpeg";
  options_.import.skip_unreadable = false;
  ExpectFailure({"broken.jpg", "--strict-photos"});
}

TEST_F(SparseStageTest, MissingColmapSaysHowToInstall) {
  WritePhotos(3);
  options_.colmap_path = (root_ / "nowhere" / "colmap").string();
  ExpectFailure({"apt-get install colmap"});
}

TEST_F(SparseStageTest, CrashedColmapIsReportedAndItsLogKept) {
  WritePhotos(3);
  options_.colmap_path = FakeColmap("echo 'Processed file [1/3]'; kill -9 $$");
  ExpectFailure({"feature_extractor", "killed by signal 9"});
  EXPECT_TRUE(fs::exists(out_ + ".failed-log.txt"));
}

TEST_F(SparseStageTest, NothingRegistered) {
  // The stand-in colmap succeeds at every step but maps nothing.
  WritePhotos(3);
  ExpectFailure({"registered none of the 3 photos", "overlap"});
}

TEST_F(SparseStageTest, NothingRegisteredFromAVideoAsksForTheFocalLength) {
  // A clip (a textured image panned sideways) carries no focal length; the
  // stand-in colmap maps nothing.
  cv::Mat texture(480, 1200, CV_8UC3);
  cv::randu(texture, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(5, 5), 1.5);
  cv::VideoWriter writer((root_ / "photos" / "clip.avi").string(),
                         cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, cv::Size(320, 240));
  ASSERT_TRUE(writer.isOpened());
  for (int i = 0; i < 40; ++i) {
    cv::Mat frame;
    cv::resize(texture(cv::Rect(20 * i, 0, 320, 240)), frame, cv::Size(320, 240));
    writer.write(frame);
  }
  writer.release();
  ExpectFailure({"COLMAP registered none of the ", " frames (no initial pair found); a video carries no "
                 "focal length (tried 0.8 times the long side): give the camera's with --focal-px"});
  // Without the guess, COLMAP's own: the same advice.
  options_.video.focal_guess = 0;
  ExpectFailure({" frames (no initial pair found); a video carries no focal length: give the "
                 "camera's with --focal-px"});
}

TEST_F(SparseStageTest, ExtractorThatLeftNoDatabaseIsReported) {
  WritePhotos(3);
  options_.native_matching = true;
  ExpectFailure({"database.db", "cannot open the COLMAP database"});
}

TEST_F(SparseStageTest, SkipUnreadableGoesOnWithoutTheBrokenPhoto) {
  WritePhotos(3);
  std::ofstream(root_ / "photos" / "broken.jpg") << "not a jpeg";
  options_.import.skip_unreadable = true;
  ExpectFailure({"registered none of the 3 photos"});  // Only the 3 good ones went on.
}

TEST_F(SparseStageTest, PhotosOfDifferentSizesWithoutExifGoOn) {
  WritePhotos(3);  // p0..p2 at 320x240.
  cv::Mat other(480, 640, CV_8UC3, cv::Scalar(10, 200, 30));
  cv::imwrite((root_ / "photos" / "z.jpg").string(), other);
  ExpectFailure({"registered none of the 4 photos"});  // Each size its own calibration.
}

TEST_F(SparseStageTest, ExistingOutputIsKept) {
  WritePhotos(3);
  fs::create_directories(out_);
  std::ofstream(fs::path(out_) / "keep.txt") << "x";
  try {
    RunSparseStage((root_ / "photos").string(), out_, options_);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("--overwrite"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::exists(fs::path(out_) / "keep.txt"));
}

TEST_F(SparseStageTest, UnwritableOutput) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: permissions are not enforced";
  WritePhotos(3);
  fs::create_directories(root_ / "ro");
  fs::permissions(root_ / "ro", fs::perms::owner_read | fs::perms::owner_exec);
  out_ = (root_ / "ro" / "out").string();
  try {
    RunSparseStage((root_ / "photos").string(), out_, options_);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create the output folder"), std::string::npos);
  }
  fs::permissions(root_ / "ro", fs::perms::owner_all);
}

TEST_F(SparseStageTest, NotAFolderAndBadOptions) {
  try {
    RunSparseStage((root_ / "missing").string(), out_, options_);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not a folder"), std::string::npos);
  }
  options_.camera_model = "FISHEYE";
  EXPECT_NE(options_.Check().message().find("camera_model"), std::string::npos);
  EXPECT_THROW(RunSparseStage((root_ / "photos").string(), out_, options_), std::invalid_argument);
  options_ = {};
  options_.import.working_megapixels = 0;
  EXPECT_NE(options_.Check().message().find("working_megapixels"), std::string::npos);
  EXPECT_TRUE(SparseStageOptions{}.Check().ok());
}

}  // namespace
}  // namespace casual3d::sfm
