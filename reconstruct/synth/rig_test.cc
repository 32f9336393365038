#include "reconstruct/synth/rig.h"

#include <cmath>

#include <gtest/gtest.h>

#include "reconstruct/synth/ground_truth_two_layer.h"
#include "reconstruct/synth/render_photo.h"
#include "reconstruct/synth/sparse_points.h"
#include "reconstruct/util/options_fields_testing.h"

namespace casual3d::synth {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

TEST(RigTest, PartialRigIsAForwardGridOnASphere) {
  RigOptions o = RigOptions::Defaults(RigKind::kPartial);
  ASSERT_TRUE(o.Check().ok());
  const Eigen::Vector3d centre(0, 1.5, 0);
  const Rig rig = MakeRig(o, centre);
  ASSERT_EQ(rig.poses.size(), 16u);
  EXPECT_EQ(rig.camera.model, geometry::CameraModelId::kPinhole);
  EXPECT_EQ(rig.camera.width, 1152);
  EXPECT_NEAR(rig.camera.FovXDeg(), 65.0, 1e-6);
  EXPECT_NEAR(rig.camera.FovYDeg(), 51.1, 0.1);
  double min_yaw = 1e9, max_yaw = -1e9, min_pitch = 1e9, max_pitch = -1e9;
  for (const geometry::Pose& p : rig.poses) {
    const Eigen::Vector3d c = p.Center();
    EXPECT_NEAR((c - centre).norm(), 0.3, 0.06);  // Radius plus hand-held jitter.
    const Eigen::Vector3d v = p.ViewingDirection();
    const double yaw = std::atan2(v.x(), -v.z()) * kRadToDeg;
    const double pitch = std::asin(v.y()) * kRadToDeg;
    min_yaw = std::min(min_yaw, yaw);
    max_yaw = std::max(max_yaw, yaw);
    min_pitch = std::min(min_pitch, pitch);
    max_pitch = std::max(max_pitch, pitch);
    // Looking outwards: the view is close to the radial direction.
    EXPECT_GT(v.dot((c - centre).normalized()), 0.98);
    // Upright: the camera's up vector points up.
    EXPECT_GT(p.UpVector().y(), 0.9);
  }
  EXPECT_NEAR(min_yaw, -27, 4);
  EXPECT_NEAR(max_yaw, 27, 4);
  EXPECT_NEAR(min_pitch, -18, 4);
  EXPECT_NEAR(max_pitch, 18, 4);
}

TEST(RigTest, SphereRigSeesEveryHorizontalDirection) {
  const RigOptions o = RigOptions::Defaults(RigKind::kSphere);
  const Rig rig = MakeRig(o, Eigen::Vector3d::Zero());
  ASSERT_EQ(rig.poses.size(), 50u);
  for (double lat : {-50.0, 0.0, 50.0}) {
    for (int k = 0; k < 360; ++k) {
      const double lon = k / kRadToDeg, la = lat / kRadToDeg;
      const Eigen::Vector3d d(std::cos(la) * std::sin(lon), std::sin(la), -std::cos(la) * std::cos(lon));
      int seen = 0;
      for (const geometry::Pose& p : rig.poses) {
        const Eigen::Vector3d x = p.R() * d;  // Direction only (far away).
        if (x.z() <= 0) continue;
        const Eigen::Vector2d px = rig.camera.Project(x);
        if (px.x() >= 0 && px.y() >= 0 && px.x() < rig.camera.width && px.y() < rig.camera.height) ++seen;
      }
      EXPECT_GE(seen, 2) << "lon " << k << " lat " << lat;
    }
  }
}

TEST(RigTest, WalkAroundCirclesTheSubjectLookingAtIt) {
  const RigOptions o = RigOptions::Defaults(RigKind::kWalkAround);
  const Rig rig = MakeRig(o, Eigen::Vector3d::Zero());
  ASSERT_EQ(rig.poses.size(), 12u);
  const Eigen::Vector3d subject(0, 0, -1.3);
  double extent = 0.0;
  for (const geometry::Pose& p : rig.poses) {
    EXPECT_NEAR((p.Center() - subject).norm(), 1.3, 0.05);
    const Eigen::Vector3d axis = p.R().row(2).transpose();
    EXPECT_GT(axis.dot((subject - p.Center()).normalized()), std::cos(4.0 / kRadToDeg));
    extent = std::max(extent, (p.Center() - rig.poses[0].Center()).norm());
  }
  // The ends of a 90-degree arc of radius 1.3 m: 1.84 m apart.
  EXPECT_NEAR(extent, 2 * 1.3 * std::sin(45.0 / kRadToDeg), 0.05);
  RigKind kind;
  EXPECT_TRUE(RigKindFromName("walk-around", &kind));
  EXPECT_EQ(kind, RigKind::kWalkAround);
  EXPECT_STREQ(RigKindName(kind), "walk-around");
}

TEST(RigTest, JitterIsSeededAndOptionsAreChecked) {
  RigOptions o = RigOptions::Defaults(RigKind::kPartial);
  const Rig a = MakeRig(o, Eigen::Vector3d::Zero());
  const Rig b = MakeRig(o, Eigen::Vector3d::Zero());
  o.seed = 2;
  const Rig c = MakeRig(o, Eigen::Vector3d::Zero());
  EXPECT_EQ(a.poses[3].translation, b.poses[3].translation);
  EXPECT_NE(a.poses[3].translation, c.poses[3].translation);
  o.width = 4;
  EXPECT_NE(o.Check().message().find("width"), std::string::npos);
  o = RigOptions::Defaults(RigKind::kPartial);
  o.num_photos = 1;
  EXPECT_NE(o.Check().message().find("photos"), std::string::npos);
  RigKind kind;
  EXPECT_TRUE(RigKindFromName("sphere", &kind));
  EXPECT_EQ(kind, RigKind::kSphere);
  EXPECT_FALSE(RigKindFromName("cube", &kind));
}

// The options structs of the synthetic capture's steps describe every field
// (reconstruct/util/options_fields.h).
TEST(SynthOptionStructs, EveryFieldIsDescribed) {
  util::testing::ExpectEveryFieldDescribed<RigOptions>("RigOptions");
  util::testing::ExpectEveryFieldDescribed<SparsePointOptions>("SparsePointOptions");
  util::testing::ExpectEveryFieldDescribed<TwoLayerOptions>("TwoLayerOptions");
  util::testing::ExpectEveryFieldDescribed<RenderOptions>("RenderOptions");
  RigOptions rig = RigOptions::Defaults(RigKind::kPartial);
  rig.fov_x_deg = 150;
  EXPECT_EQ(rig.Check().message(), "fov_x_deg 150 outside (10, 150)");
}

}  // namespace
}  // namespace casual3d::synth
