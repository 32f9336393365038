#include "reconstruct/pipeline/holdout.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <set>
#include <stdexcept>

#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/pipeline/panorama_stage.h"
#include "reconstruct/synth/synth.h"

namespace casual3d::pipeline {
namespace {

namespace fs = std::filesystem;

TEST(HoldoutTest, EveryNthOfTheSortedNames) {
  std::vector<std::string> names;
  for (int i = 19; i >= 0; --i) names.push_back("IMG_" + std::to_string(100 + i) + ".JPG");
  EXPECT_EQ(HoldoutNames(names, 8),
            (std::vector<std::string>{"IMG_100.JPG", "IMG_108.JPG", "IMG_116.JPG"}));
  EXPECT_TRUE(HoldoutNames(names, 0).empty());
  EXPECT_THROW(HoldoutNames({"a", "b"}, 1), std::invalid_argument);
  EXPECT_THROW(HoldoutNames({"a", "b", "c"}, 2), std::invalid_argument);  // Leaves only b.
}

TEST(HoldoutTest, TrainingWorkspaceLeavesOutTheHeldOutPhotos) {
  const fs::path dir =
      fs::temp_directory_path() / ("casual3d_holdout_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  synth::SynthOptions synth_options;
  synth_options.width = 96;
  synth_options.num_photos = 6;
  synth_options.panorama_width = 64;
  synth_options.write_master = false;
  synth::GenerateCapture(synth_options, (dir / "capture").string());
  const geometry::SparseModel full = geometry::ReadModel((dir / "capture" / "sparse").string());

  const std::vector<std::string> held = {"0000.jpg", "0003.jpg"};
  WriteTrainingWorkspace((dir / "capture").string(), held, (dir / "train").string());
  const geometry::SparseModel train = geometry::ReadModel((dir / "train" / "sparse").string());
  ASSERT_EQ(train.images.size(), 4u);
  std::set<int> ids;
  for (const auto& [id, image] : train.images) {
    ids.insert(id);
    EXPECT_NE(image.name, "0000.jpg");
    EXPECT_NE(image.name, "0003.jpg");
    EXPECT_EQ(full.images.at(id).name, image.name);  // Ids kept.
    EXPECT_TRUE(fs::exists(dir / "train" / "images" / image.name)) << image.name;
  }
  EXPECT_FALSE(fs::exists(dir / "train" / "images" / "0000.jpg"));
  ASSERT_GT(train.points.size(), 0u);
  EXPECT_LT(train.points.size(), full.points.size() + 1);
  for (const auto& [pid, point] : train.points) {
    EXPECT_GE(point.track.size(), 2u);
    for (const auto& t : point.track) EXPECT_TRUE(ids.count(t.image_id)) << pid;
  }
  // Top-level files come along, and the frame is the capture's.
  EXPECT_TRUE(fs::exists(dir / "train" / "capture.json"));
  const PanoramaFrame a = LoadOrComputeFrame((dir / "capture").string());
  const PanoramaFrame b = LoadOrComputeFrame((dir / "train").string());
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(a.centre[i], b.centre[i], 1e-9);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace casual3d::pipeline
