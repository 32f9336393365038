#include "reconstruct/depth/dense_units.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include <gtest/gtest.h>

#include "reconstruct/depth/dense_passes.h"
#include "reconstruct/depth/dense_report.h"
#include "reconstruct/depth/testing/toy_dense_options.h"
#include "reconstruct/depth/testing/toy_scene.h"
#include "reconstruct/io/file_util.h"

namespace casual3d::depth {
namespace {
namespace fs = std::filesystem;

class DenseUnitsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() / ("casual3d_dense_units_test_" + std::to_string(::getpid())));
    fs::create_directories(*root_);
    testing::WriteToyWorkspace(Workspace(), testing::ToyScene::Default(), 3, 3, 0.12, 240, 180, 200.0);
    // The stage in one process: the reference every unit split must match.
    reference_ = new DenseReport(RunDenseStage(Workspace(), (*root_ / "one").string(), Options()));
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*root_, ec);
    delete root_;
    delete reference_;
  }
  static std::string Workspace() { return (*root_ / "ws").string(); }
  static DenseOptions Options() { return testing::ToyDenseOptions((*root_ / "ws" / "gt").string()); }
  static DenseUnitResult Unit(const std::string& out, DensePass pass, const std::vector<int>& photos = {},
                              const DenseOptions& options = Options()) {
    return RunDenseUnit(Workspace(), (*root_ / out).string(), options, pass, photos);
  }
  // Every output file of `out` has the bytes of the one-process run's.
  static void ExpectSameFiles(const std::string& out) {
    int files = 0;
    for (const char* sub : {"depth", "confidence", "envelope"})
      for (const auto& e : fs::directory_iterator(*root_ / "one" / sub)) {
        const fs::path other = *root_ / out / sub / e.path().filename();
        ASSERT_TRUE(fs::exists(other)) << other;
        EXPECT_EQ(io::ReadFile(e.path().string()), io::ReadFile(other.string())) << other;
        ++files;
      }
    EXPECT_EQ(files, 27);
  }
  static fs::path* root_;
  static DenseReport* reference_;
};
fs::path* DenseUnitsTest::root_ = nullptr;
DenseReport* DenseUnitsTest::reference_ = nullptr;

TEST_F(DenseUnitsTest, UnitsGiveTheOneProcessOutputs) {
  const DenseUnitResult plan = Unit("units", DensePass::kPlan);
  ASSERT_EQ(plan.photos.size(), 9u);
  EXPECT_EQ(Unit("units", DensePass::kSweep, {0, 1, 2, 3}).ran, 4);
  EXPECT_EQ(Unit("units", DensePass::kSweep, {4, 5, 6, 7, 8}).ran, 5);
  // A rerun skips what is done.
  const DenseUnitResult again = Unit("units", DensePass::kSweep, {3, 4});
  EXPECT_EQ(again.ran, 0);
  EXPECT_EQ(again.skipped, 2);
  // The plan lists every photo once in its sweep order, and each photo's
  // depth unit reads its own sweep first.
  std::vector<int> order = plan.sweep_order;
  std::sort(order.begin(), order.end());
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8}));
  ASSERT_EQ(plan.needs.size(), 9u);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(plan.needs[i].front(), i);
  const fs::path costs = *root_ / "units" / ".dense-units" / "cost";
  auto cost_files = [&] { return std::distance(fs::directory_iterator(costs), fs::directory_iterator()); };
  EXPECT_EQ(cost_files(), 9);
  EXPECT_EQ(Unit("units", DensePass::kDepth, {8, 0, 5}).ran, 3);
  EXPECT_EQ(cost_files(), 6);  // A depth unit frees its photos' cost caches.
  EXPECT_EQ(Unit("units", DensePass::kDepth, {1, 2, 3, 4, 6, 7}).ran, 6);
  EXPECT_EQ(cost_files(), 0);
  const DenseUnitResult done = Unit("units", DensePass::kFinish);
  ExpectSameFiles("units");
  EXPECT_FALSE(fs::exists(*root_ / "units" / ".dense-units"));  // Spent once dense.json exists.
  EXPECT_TRUE(fs::exists(*root_ / "units" / "dense.json"));

  // The same report, timings aside.
  const DenseReport& r = done.report;
  ASSERT_EQ(r.photos.size(), reference_->photos.size());
  EXPECT_TRUE(r.evaluated);
  EXPECT_EQ(r.median_rel_error, reference_->median_rel_error);
  EXPECT_EQ(r.within_3pct, reference_->within_3pct);
  EXPECT_EQ(r.cross_view_consistency, reference_->cross_view_consistency);
  for (size_t i = 0; i < r.photos.size(); ++i) {
    PhotoReport a = r.photos[i], b = reference_->photos[i];
    for (PhotoReport* p : {&a, &b})
      p->t_sweep = p->t_envelope = p->t_mrf = p->t_refine = p->t_upsample = p->t_flat = p->t_fullres =
          p->t_visibility = 0;
    EXPECT_EQ(PhotoReportToJson(a), PhotoReportToJson(b)) << a.name;
  }
}

TEST_F(DenseUnitsTest, AnInterruptedSweepIsNotTrusted) {
  Unit("cut", DensePass::kSweep);
  // A sweep killed after its cost cache and WTA map but before its record:
  // the record is what a rerun and the next pass trust.
  const std::string stem = "0005";  // Photo 4: the names start at 0001.
  fs::remove(*root_ / "cut" / ".dense-units" / "sweep" / (stem + ".json"));
  try {
    Unit("cut", DensePass::kDepth, {4});
    FAIL() << "the depth pass ran without photo 4's sweep";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("photo 4 (" + stem + ".png) has no sweep result"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("--pass sweep --photos 4"), std::string::npos) << e.what();
  }
  try {
    Unit("cut", DensePass::kFinish);
    FAIL() << "finish ran without any depth result";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("9 of 9 photos have no depth result (photos 0,1,2,3,4,5,6,7,8)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(Unit("cut", DensePass::kSweep).ran, 1);  // Only the interrupted photo.
  Unit("cut", DensePass::kDepth);
  Unit("cut", DensePass::kFinish);
  ExpectSameFiles("cut");
}

TEST_F(DenseUnitsTest, RefusesUnitsWithOtherOptionsOrPhotos) {
  Unit("mixed", DensePass::kSweep, {0});
  DenseOptions other = Options();
  other.sweep.num_depths = 64;
  try {
    Unit("mixed", DensePass::kSweep, {1}, other);
    FAIL() << "a unit with other options shared the folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("plan.json: made from other photos or with other options"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(Unit("mixed", DensePass::kSweep, {9}), std::invalid_argument);
  // A unit refused for what it lacks writes nothing.
  EXPECT_THROW(Unit("fresh", DensePass::kDepth, {2}), std::runtime_error);
  EXPECT_THROW(Unit("fresh", DensePass::kFinish), std::runtime_error);
  EXPECT_FALSE(fs::exists(*root_ / "fresh"));
}

TEST_F(DenseUnitsTest, UnitsReadOnlyThePhotosTheyNeed) {
  // A copy of the workspace with one photo that photo 0's sweep does not
  // read made undecodable: the sweep runs, the plan (which checks every
  // photo) and a unit that reads it name it.
  const fs::path ws = *root_ / "ws-one-bad";
  fs::copy(Workspace(), ws, fs::copy_options::recursive);
  DenseOptions options = Options();
  options.num_neighbors = 2;
  const DensePlan plan = PlanDense(ws.string(), options, /*load_pixels=*/false);
  EXPECT_FALSE(HasViewPixels(plan.ws, 0));
  const std::vector<int> read = PhotosRead(plan, {0});
  ASSERT_EQ(read.size(), 3u);
  int unread = 0;
  while (std::find(read.begin(), read.end(), unread) != read.end()) ++unread;
  const std::string bad_name = plan.ws.views[unread].name;
  io::WriteFileAtomic((ws / "images" / bad_name).string(), "not a photo");

  const auto unit = [&](DensePass pass, const std::vector<int>& photos) {
    return RunDenseUnit(ws.string(), (*root_ / "one-bad").string(), options, pass, photos);
  };
  EXPECT_EQ(unit(DensePass::kSweep, {0}).ran, 1);
  for (DensePass pass : {DensePass::kPlan, DensePass::kSweep}) {
    try {
      unit(pass, {unread});
      FAIL() << "a unit read the undecodable " << bad_name;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(bad_name), std::string::npos) << e.what();
    }
  }
}

TEST_F(DenseUnitsTest, UnitsAfterThePlanReadItsRecordNotTheModel) {
  const fs::path ws = *root_ / "ws-model-gone";
  fs::copy(Workspace(), ws, fs::copy_options::recursive);
  const auto unit = [&](DensePass pass, const std::vector<int>& photos) {
    return RunDenseUnit(ws.string(), (*root_ / "model-gone").string(), Options(), pass, photos);
  };
  unit(DensePass::kPlan, {});
  fs::remove_all(ws / "sparse");
  EXPECT_EQ(unit(DensePass::kSweep, {0}).ran, 1);
  // The plan pass itself reads the workspace again, and says what is missing.
  EXPECT_THROW(unit(DensePass::kPlan, {}), std::runtime_error);
}

TEST_F(DenseUnitsTest, TheFinishUnitReadsTheGreyImagesOfTheOneProcess) {
  // The finish unit reads each photo's full-resolution grey image on its
  // own (ReadViewGrayFull); its bytes must be those LoadViewPixels gives.
  const DensePlan plan = PlanDense(Workspace(), Options());
  for (int i = 0; i < plan.size(); ++i)
    EXPECT_EQ(ReadViewGrayFull(plan.ws, i).vector(), plan.ws.views[i].gray_full.vector()) << i;
}

TEST(ParsePhotoListTest, IndicesAndRanges) {
  EXPECT_EQ(ParsePhotoList("3"), std::vector<int>({3}));
  EXPECT_EQ(ParsePhotoList("5-7,0,6"), std::vector<int>({0, 5, 6, 7}));
  for (const char* bad : {"", "a", "1,", "3-1", "-2", "1-", "1.5", "2-x", " 1"})
    EXPECT_THROW(ParsePhotoList(bad), std::invalid_argument) << bad;
}

TEST(DensePassTest, Names) {
  DensePass p;
  EXPECT_TRUE(DensePassFromName("depth", &p));
  EXPECT_EQ(p, DensePass::kDepth);
  EXPECT_FALSE(DensePassFromName("mrf", &p));
}

TEST(PhotoReportJsonTest, RoundTripIsExact) {
  PhotoReport r;
  r.name = "a/b.jpg";
  r.neighbors = {"c.jpg"};
  r.mrf_energy = 0.1 + 0.2;
  r.near_m = 1.0 / 3.0;
  r.anchors = {1, 2, 3, 4};
  r.flat_pixels = 1LL << 40;
  r.stages.push_back({"gc", 0.7, 1e-300});
  const PhotoReport back = PhotoReportFromJson(nlohmann::json::parse(PhotoReportToJson(r).dump()));
  EXPECT_EQ(back.mrf_energy, r.mrf_energy);
  EXPECT_EQ(back.near_m, r.near_m);
  EXPECT_EQ(back.flat_pixels, r.flat_pixels);
  ASSERT_EQ(back.stages.size(), 1u);
  EXPECT_EQ(back.stages[0].precision, 1e-300);
  EXPECT_EQ(PhotoReportToJson(back), PhotoReportToJson(r));
}

}  // namespace
}  // namespace casual3d::depth
