#include "reconstruct/eval/reference_alignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>

#include "base/testing/scratch_dir.h"

namespace casual3d::eval {
namespace {

// Six cameras on a 0.3 m arc looking outwards (a casual capture), with a
// little roll each, in the reference's world.
geometry::SparseModel ReferenceModel() {
  geometry::SparseModel m;
  geometry::Camera camera;
  camera.camera_id = 1;
  camera.model = geometry::CameraModelId::kPinhole;
  camera.width = 640;
  camera.height = 480;
  camera.params = {500, 500, 320, 240};
  m.cameras[1] = camera;
  for (int i = 0; i < 6; ++i) {
    const double yaw = (i - 2.5) * 0.2, pitch = (i % 2 ? 0.15 : -0.1);
    const Eigen::Vector3d dir(std::cos(pitch) * std::sin(yaw), std::sin(pitch),
                              -std::cos(pitch) * std::cos(yaw));
    const Eigen::Vector3d centre = Eigen::Vector3d(0.1, 1.5, 2.0) + 0.3 * dir;
    geometry::ModelImage image;
    image.image_id = i + 1;
    image.camera_id = 1;
    image.name = "photo_" + std::to_string(i) + ".jpg";
    image.pose = geometry::Pose::LookAt(centre, centre + dir, Eigen::Vector3d(0.05 * i, 1, 0));
    m.images[i + 1] = image;
  }
  return m;
}

// A similarity with rotation, scale and translation.
geometry::Similarity3 SomeSimilarity() {
  geometry::Similarity3 s;
  s.scale = 3.7;
  s.R = Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  s.t = Eigen::Vector3d(-4, 2.5, 11);
  return s;
}

TEST(ReferenceAlignmentTest, PosesThePhotosTheModelLacksInItsWorld) {
  const geometry::SparseModel reference = ReferenceModel();
  // The 3D photo's own model: the reference in another world (what
  // structure from motion gives), without photos 1 and 4.
  const geometry::Similarity3 to_model = SomeSimilarity();
  geometry::SparseModel model;
  std::map<std::string, geometry::Pose> expected;
  for (const auto& [id, image] : reference.images) {
    geometry::ModelImage moved = image;
    moved.image_id = 100 + id;  // Ids differ between models; names match.
    moved.pose = to_model.ApplyToPose(image.pose);
    expected[image.name] = moved.pose;
    if (id != 2 && id != 5) model.images[moved.image_id] = moved;
  }
  ReferenceAlignment a;
  const geometry::SparseModel posed = PosesFromReference(
      model, reference, {"photo_1.jpg", "photo_4.jpg"}, "model", "reference", &a);
  EXPECT_EQ(a.num_common, 4);
  EXPECT_NEAR(a.model_to_reference.scale, 1.0 / to_model.scale, 1e-9);
  EXPECT_LT(a.mean_rotation_error_deg, 1e-6);
  EXPECT_LT(a.max_centre_error, 1e-9);
  ASSERT_EQ(posed.images.size(), 6u);
  EXPECT_EQ(posed.cameras.at(1).params, reference.cameras.at(1).params);
  for (const auto& [id, image] : posed.images) {
    const geometry::Pose& want = expected.at(image.name);
    EXPECT_LT((image.pose.Center() - want.Center()).norm(), 1e-9) << image.name;
    EXPECT_LT(geometry::RotationAngleDeg(image.pose.rotation, want.rotation), 1e-6) << image.name;
    // A point in front of the camera projects alike in both worlds.
    const Eigen::Vector3d x_ref = reference.images.at(id).pose.CameraToWorld({0.2, -0.1, 1.5});
    const Eigen::Vector3d in_cam = image.pose.WorldToCamera(to_model.Apply(x_ref));
    EXPECT_LT((in_cam / in_cam.z() - Eigen::Vector3d(0.2 / 1.5, -0.1 / 1.5, 1)).norm(), 1e-9);
  }
}

TEST(ReferenceAlignmentTest, FewerThanThreeCommonPhotosIsAClearError) {
  const geometry::SparseModel reference = ReferenceModel();
  geometry::SparseModel model;
  for (int id : {1, 2, 3}) model.images[id] = reference.images.at(id);
  model.images[2].name = "elsewhere.jpg";
  try {
    // photo_0 and photo_2 in common, photo_2 evaluated: one left.
    PosesFromReference(model, reference, {"photo_2.jpg"}, "out/work/sparse/sparse", "ref/sparse",
                       nullptr);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "ref/sparse: 1 photo in common with the 3D photo's model out/work/sparse/sparse (by "
              "file name, the evaluated photos left out); 3 are needed to align them");
  }
}

class FindReferenceModelTest : public casual3d::testing::TestWithScratchDir {};

TEST_F(FindReferenceModelTest, TheFolderOrItsSparseSubfolder) {
  const std::string dir = scratch_.Path("capture");
  std::filesystem::create_directories(dir + "/sparse");
  try {
    FindReferenceModel(dir);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).find(dir + ": no COLMAP model"), 0u) << e.what();
  }
  std::ofstream(dir + "/sparse/cameras.txt") << "# none\n";
  EXPECT_EQ(FindReferenceModel(dir), dir + "/sparse");
  EXPECT_EQ(FindReferenceModel(dir + "/sparse"), dir + "/sparse");
  try {
    FindReferenceModel(scratch_.Path("missing"));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).find(scratch_.Path("missing") + ": not a folder"), 0u);
  }
}

}  // namespace
}  // namespace casual3d::eval
