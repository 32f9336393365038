#include "reconstruct/depth/dense_stage.h"

#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "reconstruct/depth/depth_metrics.h"
#include "reconstruct/depth/testing/toy_dense_options.h"
#include "reconstruct/depth/testing/toy_scene.h"
#include "reconstruct/io/exr_io.h"

namespace casual3d::depth {
namespace {
namespace fs = std::filesystem;

class DenseStageTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() /
                         ("casual3d_dense_test_" + std::to_string(::getpid())));
    fs::create_directories(*root_);
    testing::WriteToyWorkspace((*root_ / "ws").string(), testing::ToyScene::Default(), 3, 3, 0.12,
                               240, 180, 200.0);
  }
  static void TearDownTestSuite() {
    if (std::getenv("CASUAL3D_KEEP_TEST_OUTPUT")) return;  // For inspecting debug images.
    std::error_code ec;
    fs::remove_all(*root_, ec);
    delete root_;
  }
  static DenseOptions Options() { return testing::ToyDenseOptions((*root_ / "ws" / "gt").string()); }
  static fs::path* root_;
};
fs::path* DenseStageTest::root_ = nullptr;

TEST_F(DenseStageTest, ReconstructsTheToySceneAccurately) {
  DenseOptions o = Options();
  o.debug = true;
  const fs::path out = *root_ / "out";
  const DenseReport r = RunDenseStage((*root_ / "ws").string(), out.string(), o);
  ASSERT_EQ(r.photos.size(), 9u);
  ASSERT_TRUE(r.evaluated);
  std::printf("toy: median rel %.4f within3 %.4f floaters %.4f cross-view %.4f\n", r.median_rel_error,
              r.within_3pct, r.near_floaters, r.cross_view_consistency);
  // Measured: median 0.05%, 94.6% within 3%, 0.15% near floaters (what is
  // left of the window fattening at the board's and the pole's edges at this
  // tiny 120x90 working size after the edge-aware median, the colour-weighted
  // texture measure and the free-space check; see below without the check).
  EXPECT_LE(r.median_rel_error, 0.003);
  EXPECT_GE(r.within_3pct, 0.91);
  EXPECT_LE(r.near_floaters, 0.005);
  // Consistent depth maps agree across views without any ground truth
  // (measured 87.2%; 91.0% with the far bias of 0.02 that the dense stage no
  // longer applies by default, when the toy's sky went to the far plane,
  // where the views agree trivially; the real captures rose without it).
  EXPECT_GE(r.cross_view_consistency, 0.85);
  for (const PhotoReport& p : r.photos) EXPECT_GT(p.cross_view_consistency, 0.0) << p.name;
  // Outputs exist at full resolution; the cost cache is gone.
  const ImageF d = io::ReadExrChannels((out / "depth" / "0005.exr").string(), {"Z"});
  EXPECT_EQ(d.width(), 240);
  EXPECT_EQ(d.height(), 180);
  EXPECT_TRUE(fs::exists(out / "confidence" / "0005.exr"));
  EXPECT_TRUE(fs::exists(out / "envelope" / "0005.exr"));
  EXPECT_TRUE(fs::exists(out / "dense.json"));
  EXPECT_TRUE(fs::exists(out / "debug" / "0005_bilateral.png"));
  EXPECT_FALSE(fs::exists(out / ".dense-cache"));
  // The pruning stages raise precision (Fig. 6): anchors after the last
  // filter are more precise than the raw WTA and the envelope rarely cuts content.
  for (const PhotoReport& p : r.photos) {
    ASSERT_EQ(p.stages.size(), 4u);
    EXPECT_GE(p.stages[3].precision, p.stages[0].precision) << p.name;
    EXPECT_GE(p.stages[3].precision, 0.85) << p.name;
    EXPECT_GE(p.stages[3].completeness, 0.5) << p.name;
    // Measured at most 5.7% (photo 0008; 3% before the far plane moved to
    // 100x the near plane, with the labels added beyond the toy's own range).
    EXPECT_LE(p.envelope_error, 0.07) << p.name;
  }
}

TEST_F(DenseStageTest, FreeSpaceCheckRemovesWhatTheFatteningLeft) {
  DenseOptions o = Options();
  o.visibility.enabled = false;
  const DenseReport off = RunDenseStage((*root_ / "ws").string(), (*root_ / "out_nofs").string(), o);
  ASSERT_TRUE(off.evaluated);
  std::printf("toy without the free-space check: median rel %.4f within3 %.4f floaters %.4f cross-view %.4f\n",
              off.median_rel_error, off.within_3pct, off.near_floaters, off.cross_view_consistency);
  for (const PhotoReport& p : off.photos) EXPECT_EQ(p.moved_back, 0) << p.name;
  o.visibility.enabled = true;
  const DenseReport on = RunDenseStage((*root_ / "ws").string(), (*root_ / "out_fs").string(), o);
  long long moved = 0;
  for (const PhotoReport& p : on.photos) moved += p.moved_back;
  EXPECT_GT(moved, 0);
  // Measured: near floaters 0.29% -> 0.15%, within 3% 94.3% -> 94.6%,
  // cross-view consistency 72.6% -> 87.2%.
  EXPECT_LE(on.near_floaters, 0.75 * off.near_floaters);
  EXPECT_GT(on.within_3pct, off.within_3pct);
  EXPECT_GT(on.cross_view_consistency, off.cross_view_consistency);
}

TEST_F(DenseStageTest, RejectsAMissingWorkspaceWithAClearMessage) {
  try {
    RunDenseStage((*root_ / "nope").string(), (*root_ / "out2").string(), Options());
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nope"), std::string::npos) << e.what();
  }
  DenseOptions bad = Options();
  bad.working_scale = 2.0;
  EXPECT_THROW(RunDenseStage((*root_ / "ws").string(), (*root_ / "out3").string(), bad),
               std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth
