#include "reconstruct/pipeline/panorama_inputs.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "reconstruct/io/exr_io.h"

namespace casual3d::pipeline {
namespace {
namespace fs = std::filesystem;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Runs ForEachPanoramaPhoto over 8 photos, of which 2 and 5 fail; returns
// the error thrown.
std::string FirstError(int threads, std::vector<std::atomic<int>>* started) {
  try {
    ForEachPanoramaPhoto(8, threads, [&](int i) {
      ++(*started)[i];
      if (i == 2 || i == 5) throw std::runtime_error("photo " + std::to_string(i));
    });
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(PanoramaInputsTest, TheErrorOfTheFirstFailingPhotoInModelOrderIsThrown) {
  for (int threads : {1, 2, 4}) {
    for (int run = 0; run < 20; ++run) {
      std::vector<std::atomic<int>> started(8);
      EXPECT_EQ(FirstError(threads, &started), "photo 2") << threads << " threads";
      // Every photo before it ran, as a loop in order would have.
      for (int i = 0; i < 2; ++i) EXPECT_EQ(started[i], 1);
      if (threads == 1) {
        for (int i = 3; i < 8; ++i) EXPECT_EQ(started[i], 0) << "photo " << i << " started after the failure";
      }
    }
  }
}

TEST(PanoramaInputsTest, SkyIsBeyondTheLargestFiniteDepthOfAllPhotos) {
  const fs::path dir = fs::temp_directory_path() / ("casual3d_panorama_inputs_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::vector<std::vector<float>> maps = {
      {1.0f, kInf, 2.5f, -1.0f}, {kNaN, 4.0f, 0.0f, 3.0f}, {kInf, kInf, kInf, kInf}};
  std::vector<PanoramaPhoto> photos(maps.size());
  for (size_t k = 0; k < maps.size(); ++k) {
    ImageF depth(2, 2, 1);
    depth.vector() = maps[k];
    photos[k].depth_path = (dir / (std::to_string(k) + ".exr")).string();
    io::WriteExr(photos[k].depth_path, depth, {"Z"});
  }
  for (int threads : {1, 3}) EXPECT_EQ(SkyDepth(0.0, photos, threads), 1.5 * 4.0f);
  EXPECT_EQ(SkyDepth(0.0, {photos[2]}, 1), 1000.0);  // No finite depth at all.
  EXPECT_EQ(SkyDepth(20.0, {PanoramaPhoto()}, 1), 20.0);  // Given: no map is read.
  photos[1].depth_path = (dir / "missing.exr").string();
  EXPECT_THROW(SkyDepth(0.0, photos, 2), std::exception);
  fs::remove_all(dir);

  ImageF depth(2, 2, 1);
  depth.vector() = maps[1];
  FillSky(7.5, &depth);
  EXPECT_EQ(depth.vector(), (std::vector<float>{7.5f, 4.0f, 7.5f, 3.0f}));
}

}  // namespace
}  // namespace casual3d::pipeline
