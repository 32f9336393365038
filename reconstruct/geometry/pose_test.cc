#include "reconstruct/geometry/pose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace casual3d::geometry {
namespace {

void ExpectVectorNear(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tol) {
  EXPECT_NEAR((a - b).norm(), 0.0, tol) << "got " << a.transpose() << ", want " << b.transpose();
}

Pose SomePose() {
  Pose pose;
  pose.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1.0, 0.2).normalized()));
  pose.translation = Eigen::Vector3d(0.5, -1.25, 3.0);
  return pose;
}

TEST(PoseTest, IdentityLooksDownPlusZWithUpMinusY) {
  const Pose identity;
  ExpectVectorNear(identity.Center(), Eigen::Vector3d::Zero(), 1e-15);
  ExpectVectorNear(identity.ViewingDirection(), Eigen::Vector3d(0, 0, 1), 1e-15);
  ExpectVectorNear(identity.UpVector(), Eigen::Vector3d(0, -1, 0), 1e-15);
}

TEST(PoseTest, CenterMapsToCameraOrigin) {
  const Pose pose = SomePose();
  ExpectVectorNear(pose.WorldToCamera(pose.Center()), Eigen::Vector3d::Zero(), 1e-12);
  ExpectVectorNear(pose.Center(), -(pose.R().transpose() * pose.translation), 1e-12);
  // A point one metre along the viewing direction is at camera (0, 0, 1).
  ExpectVectorNear(pose.WorldToCamera(pose.Center() + pose.ViewingDirection()),
                   Eigen::Vector3d(0, 0, 1), 1e-12);
  ExpectVectorNear(pose.WorldToCamera(pose.Center() + pose.UpVector()), Eigen::Vector3d(0, -1, 0),
                   1e-12);
}

TEST(PoseTest, MatrixAndTransformsAgree) {
  const Pose pose = SomePose();
  const Eigen::Vector3d x(1.5, 2.0, -0.75);
  const Eigen::Matrix<double, 3, 4> P = pose.Matrix3x4();
  ExpectVectorNear(P * x.homogeneous(), pose.WorldToCamera(x), 1e-12);
  ExpectVectorNear(pose.CameraToWorld(pose.WorldToCamera(x)), x, 1e-12);
}

TEST(PoseTest, InverseComposesToIdentity) {
  const Pose pose = SomePose();
  const Pose inverse = pose.Inverse();
  const Eigen::Vector3d x(-0.2, 0.9, 4.0);
  ExpectVectorNear(inverse.WorldToCamera(pose.WorldToCamera(x)), x, 1e-12);
  // The inverse's translation is the camera centre (camera-to-world).
  ExpectVectorNear(inverse.translation, pose.Center(), 1e-12);
}

TEST(PoseTest, FromCenterPlacesCamera) {
  const Eigen::Matrix3d R = SomePose().R();
  const Eigen::Vector3d c(3.0, -1.0, 2.0);
  const Pose pose = Pose::FromCenter(R, c);
  ExpectVectorNear(pose.Center(), c, 1e-12);
  EXPECT_NEAR((pose.R() - R).norm(), 0.0, 1e-12);
}

TEST(PoseTest, LookAtPointsAtTargetWithUp) {
  const Eigen::Vector3d center(1.0, 2.0, 3.0), target(4.0, 2.5, -1.0), up(0, 1, 0);
  const Pose pose = Pose::LookAt(center, target, up);
  ExpectVectorNear(pose.Center(), center, 1e-12);
  ExpectVectorNear(pose.ViewingDirection(), (target - center).normalized(), 1e-12);
  // The target is on the optical axis.
  const Eigen::Vector3d t_cam = pose.WorldToCamera(target);
  EXPECT_NEAR(t_cam.x(), 0.0, 1e-12);
  EXPECT_NEAR(t_cam.y(), 0.0, 1e-12);
  EXPECT_NEAR(t_cam.z(), (target - center).norm(), 1e-12);
  // Image up is the projection of `up` perpendicular to the viewing direction.
  const Eigen::Vector3d d = pose.ViewingDirection();
  const Eigen::Vector3d expected_up = (up - up.dot(d) * d).normalized();
  ExpectVectorNear(pose.UpVector(), expected_up, 1e-12);
  // A proper rotation (no mirror).
  EXPECT_NEAR(pose.R().determinant(), 1.0, 1e-12);
  // A point to the world's right of the view (for +Y up) appears on image right.
  const Pose forward = Pose::LookAt(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, -1), up);
  EXPECT_GT(forward.WorldToCamera(Eigen::Vector3d(1, 0, -5)).x(), 0.0);
  EXPECT_LT(forward.WorldToCamera(Eigen::Vector3d(0, 1, -5)).y(), 0.0);
}

TEST(PoseTest, LookAtAlongUpStillGivesRotation) {
  const Pose pose =
      Pose::LookAt(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 5, 0), Eigen::Vector3d(0, 1, 0));
  ExpectVectorNear(pose.ViewingDirection(), Eigen::Vector3d(0, 1, 0), 1e-12);
  EXPECT_NEAR(pose.R().determinant(), 1.0, 1e-12);
}

TEST(PoseTest, RotationAngle) {
  const Eigen::Quaterniond a(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
  const Eigen::Quaterniond b(Eigen::AngleAxisd(0.3 + 0.2, Eigen::Vector3d::UnitY()));
  EXPECT_NEAR(RotationAngleDeg(a, b), 0.2 * 180.0 / M_PI, 1e-10);
  EXPECT_NEAR(RotationAngleDeg(a, a), 0.0, 1e-6);
  // q and -q are the same rotation.
  Eigen::Quaterniond neg = a;
  neg.coeffs() *= -1.0;
  EXPECT_NEAR(RotationAngleDeg(a, neg), 0.0, 1e-6);
  const Eigen::Quaterniond c(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  EXPECT_NEAR(RotationAngleDeg(Eigen::Quaterniond::Identity(), c), 180.0, 1e-9);
}

TEST(SimilarityTest, ApplyToPoseKeepsImages) {
  Similarity3 sim;
  sim.scale = 2.5;
  sim.R = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  sim.t = Eigen::Vector3d(-4, 0.5, 7);
  const Pose pose = SomePose();
  const Pose moved = sim.ApplyToPose(pose);
  // A world point and its image: the transformed point in the transformed
  // camera has the same direction (depth scales by `scale`).
  const Eigen::Vector3d x(0.3, -0.4, 5.0);
  const Eigen::Vector3d before = pose.WorldToCamera(x);
  const Eigen::Vector3d after = moved.WorldToCamera(sim.Apply(x));
  ExpectVectorNear(after, sim.scale * before, 1e-10);
}

TEST(SimilarityTest, RecoversKnownSimilarityWithNoise) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-5.0, 5.0);
  std::normal_distribution<double> noise(0.0, 0.01);
  Similarity3 truth;
  truth.scale = 0.37;
  truth.R = Eigen::AngleAxisd(2.0, Eigen::Vector3d(-0.3, 0.8, 0.5).normalized()).toRotationMatrix();
  truth.t = Eigen::Vector3d(1.0, -2.0, 0.25);
  std::vector<Eigen::Vector3d> src, dst;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d x(uniform(rng), uniform(rng), uniform(rng));
    src.push_back(x);
    dst.push_back(truth.Apply(x) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  }
  Similarity3 estimate;
  ASSERT_TRUE(EstimateSimilarity(src, dst, &estimate));
  EXPECT_NEAR(estimate.scale, truth.scale, 1e-3);
  const double angle_deg =
      RotationAngleDeg(Eigen::Quaterniond(estimate.R), Eigen::Quaterniond(truth.R));
  EXPECT_LT(angle_deg, 0.1);
  ExpectVectorNear(estimate.t, truth.t, 5e-3);
  EXPECT_NEAR(estimate.R.determinant(), 1.0, 1e-12);

  // Exact data is recovered to rounding.
  for (size_t i = 0; i < src.size(); ++i) dst[i] = truth.Apply(src[i]);
  ASSERT_TRUE(EstimateSimilarity(src, dst, &estimate));
  EXPECT_NEAR(estimate.scale, truth.scale, 1e-12);
  EXPECT_NEAR((estimate.R - truth.R).norm(), 0.0, 1e-12);
  ExpectVectorNear(estimate.t, truth.t, 1e-12);
}

TEST(SimilarityTest, MinimalThreePointsAndMirrorFree) {
  // Three points; the target is a mirror image would need det -1: Umeyama's
  // correction must still return a rotation.
  const std::vector<Eigen::Vector3d> src = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<Eigen::Vector3d> dst = {{0, 0, 0}, {0, 2, 0}, {2, 0, 0}};
  Similarity3 sim;
  ASSERT_TRUE(EstimateSimilarity(src, dst, &sim));
  EXPECT_NEAR(sim.R.determinant(), 1.0, 1e-12);
  EXPECT_NEAR(sim.scale, 2.0, 1e-12);
  // A planar swap of x and y is a rotation of 180 degrees about (1, 1, 0).
  for (size_t i = 0; i < src.size(); ++i) ExpectVectorNear(sim.Apply(src[i]), dst[i], 1e-12);
}

TEST(SimilarityTest, RejectsDegenerateInput) {
  Similarity3 sim;
  EXPECT_FALSE(EstimateSimilarity({{0, 0, 0}, {1, 1, 1}}, {{0, 0, 0}, {1, 1, 1}}, &sim));
  // Collinear points.
  EXPECT_FALSE(EstimateSimilarity({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}},
                                  {{1, 0, 0}, {2, 1, 1}, {3, 2, 2}, {4, 3, 3}}, &sim));
  // Coincident points.
  EXPECT_FALSE(EstimateSimilarity({{1, 1, 1}, {1, 1, 1}, {1, 1, 1}},
                                  {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, &sim));
  // Mismatched sizes.
  EXPECT_FALSE(EstimateSimilarity({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, 0}, {1, 0, 0}}, &sim));
}

}  // namespace
}  // namespace casual3d::geometry
