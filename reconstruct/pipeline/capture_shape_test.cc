#include "reconstruct/pipeline/capture_shape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "reconstruct/util/options_fields_testing.h"

namespace casual3d::pipeline {
namespace {

constexpr double kDeg = kPi / 180.0;

// A scene point and the side it is seen from.
struct ScenePoint {
  Eigen::Vector3d xyz;
  Eigen::Vector3d normal;  // Unit; seen by cameras on its positive side.
};

// Unit direction for yaw (about +Y, 0 = -Z) and pitch (up).
Eigen::Vector3d Direction(double yaw_deg, double pitch_deg) {
  const double y = yaw_deg * kDeg, p = pitch_deg * kDeg;
  return {std::cos(p) * std::sin(y), std::sin(p), -std::cos(p) * std::cos(y)};
}

// Points on a sphere of `radius` around `centre`, facing inwards (`inwards`)
// or outwards.
std::vector<ScenePoint> SpherePoints(const Eigen::Vector3d& centre, double radius, int count,
                                     bool inwards, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<ScenePoint> points;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d d = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    points.push_back({centre + radius * d, inwards ? -d : d});
  }
  return points;
}

// A COLMAP-like model: PINHOLE 640 x 480 photos (65 degrees across) named
// img_00.jpg, ... at `centres` looking along `forwards`; every point a photo
// sees (inside its image, from its side) is observed.
class ModelBuilder {
 public:
  ModelBuilder() {
    geometry::Camera camera;
    camera.camera_id = 1;
    camera.model = geometry::CameraModelId::kPinhole;
    camera.width = 640;
    camera.height = 480;
    const double f = 320.0 / std::tan(32.5 * kDeg);
    camera.params = {f, f, 320.0, 240.0};
    model_.cameras[1] = camera;
  }

  void AddPhoto(const Eigen::Vector3d& centre, const Eigen::Vector3d& forward) {
    geometry::ModelImage image;
    image.image_id = static_cast<int>(model_.images.size()) + 1;
    image.camera_id = 1;
    char name[32];
    std::snprintf(name, sizeof name, "img_%02d.jpg", image.image_id - 1);
    image.name = name;
    image.pose = geometry::Pose::LookAt(centre, centre + forward, Eigen::Vector3d::UnitY());
    model_.images[image.image_id] = image;
  }

  // Adds `points`, observed by every photo that sees them.
  void AddPoints(const std::vector<ScenePoint>& points) {
    const geometry::Camera& camera = model_.cameras.at(1);
    for (const ScenePoint& p : points) {
      geometry::Point3D point;
      point.point3d_id = model_.points.size() + 1;
      point.xyz = p.xyz;
      for (auto& [id, image] : model_.images) {
        const Eigen::Vector3d c = image.pose.Center();
        if (p.normal.dot(c - p.xyz) <= 0) continue;
        const Eigen::Vector3d q = image.pose.R() * p.xyz + image.pose.translation;
        if (q.z() <= 0) continue;
        const Eigen::Vector2d uv = camera.Project(q);
        if (uv.x() < 0 || uv.x() > camera.width || uv.y() < 0 || uv.y() > camera.height) continue;
        point.track.push_back({id, static_cast<int>(image.points2d.size())});
        image.points2d.push_back({uv, point.point3d_id});
      }
      if (point.track.size() >= 2) model_.points[point.point3d_id] = point;
      else
        for (const auto& t : point.track) model_.images[t.image_id].points2d.pop_back();
    }
  }

  // `count` points observed by the photos `image_ids` whatever they see (a
  // link made by hand), 3 m in front of the first.
  void AddSharedPoints(int count, const std::vector<int>& image_ids) {
    const geometry::ModelImage& first = model_.images.at(image_ids[0]);
    const Eigen::Vector3d xyz = first.pose.Center() + 3.0 * first.pose.R().row(2).transpose();
    for (int i = 0; i < count; ++i) {
      geometry::Point3D point;
      point.point3d_id = model_.points.size() + 1;
      point.xyz = xyz;
      for (int id : image_ids) {
        geometry::ModelImage& image = model_.images.at(id);
        point.track.push_back({id, static_cast<int>(image.points2d.size())});
        image.points2d.push_back({Eigen::Vector2d(320, 240), point.point3d_id});
      }
      model_.points[point.point3d_id] = point;
    }
  }

  // The frame centred at the mean camera centre (axes of the world).
  PanoramaFrame Frame() const {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& [id, image] : model_.images) mean += image.pose.Center();
    mean /= static_cast<double>(model_.images.size());
    PanoramaFrame frame;
    for (int k = 0; k < 3; ++k) frame.centre[k] = mean[k];
    return frame;
  }

  const geometry::SparseModel& model() const { return model_; }

 private:
  geometry::SparseModel model_;
};

// Points on a wall 5 m behind the rig (z = 5), facing it.
std::vector<ScenePoint> BackWall() {
  std::vector<ScenePoint> back;
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-6, 6);
  for (int i = 0; i < 1500; ++i) back.push_back({{u(rng), 0.5 * u(rng), 5.0}, -Eigen::Vector3d::UnitZ()});
  return back;
}

// A phone at arm's length (0.3 m) turned over a 4 x 4 grid of directions
// (yaw +-30, pitch +-20 degrees) from one spot, with a scene 1-6 m away.
ModelBuilder TurningCapture() {
  ModelBuilder b;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d d = Direction(-30.0 + 20.0 * c, 20.0 - 13.3 * r);
      b.AddPhoto(0.3 * d, d);
    }
  b.AddPoints(SpherePoints(Eigen::Vector3d::Zero(), 6.0, 6000, true, 1));
  b.AddPoints(SpherePoints(Eigen::Vector3d::Zero(), 1.5, 1500, true, 2));
  return b;
}

TEST(CaptureShape, TurningOnTheSpotGetsNoWarning) {
  const ModelBuilder b = TurningCapture();
  const CaptureShape s = MeasureCaptureShape(b.model(), b.Frame(), {}, true);
  EXPECT_EQ(s.num_photos, 16);
  EXPECT_EQ(s.num_registered, 16);
  // The frame's centre is the mean camera centre, ahead of the pivot.
  EXPECT_GT(s.spread, 0.1);
  EXPECT_LT(s.spread, 0.3);
  EXPECT_NEAR(s.off_axis, 0.0, 1e-3);  // The camera swung about one point.
  // The nearest points: the 1.5 m sphere, 1.2 m ahead of a camera 0.3 m out.
  EXPECT_GT(s.near_depth, 1.0);
  EXPECT_LT(s.near_depth, 1.5);
  EXPECT_FALSE(s.walked);
  EXPECT_FALSE(s.narrow);
  // 60 x 40 degrees swept plus one photo's 65 x 51: several photos' worth.
  EXPECT_GT(s.sphere_fraction, 2.0 * s.photo_sphere_fraction);
  ASSERT_EQ(s.groups.size(), 1u);
  EXPECT_EQ(s.groups[0].size(), 16u);
  EXPECT_FALSE(s.warning());
  ASSERT_EQ(s.advice.size(), 1u);  // The description only.
  char moved[64];
  std::snprintf(moved, sizeof moved, "The camera moved %.2f m; the nearest objects were %.2f m away",
                s.extent, s.near_depth);
  EXPECT_EQ(s.advice[0].rfind(moved, 0), 0u) << s.advice[0];
  EXPECT_LT(s.extent, 0.6);  // Less than the arm's span.
}

TEST(CaptureShape, WalkAroundRingWarnsWithTheDistance) {
  // 24 photos on a ring of 2 m around an object (a 0.5 m ball) with a
  // background 8 m away, all looking at the object.
  ModelBuilder b;
  for (int i = 0; i < 24; ++i) {
    const Eigen::Vector3d d = Direction(15.0 * i, 0.0);
    b.AddPhoto(-2.0 * d, d);
  }
  b.AddPoints(SpherePoints(Eigen::Vector3d::Zero(), 0.5, 3000, false, 3));
  b.AddPoints(SpherePoints(Eigen::Vector3d::Zero(), 8.0, 6000, true, 4));
  const CaptureShape s = MeasureCaptureShape(b.model(), b.Frame(), {}, true);
  EXPECT_NEAR(s.extent, 4.0, 1e-6);  // The ring's diameter.
  EXPECT_NEAR(s.spread, 2.0, 1e-6);
  EXPECT_NEAR(s.off_axis, 2.0, 1e-6);  // All of it backwards.
  EXPECT_NEAR(s.near_depth, 1.5, 0.15);  // The ball's front.
  EXPECT_TRUE(s.walked);
  EXPECT_TRUE(s.around);
  EXPECT_TRUE(s.warning());
  ASSERT_GE(s.advice.size(), 2u);
  EXPECT_EQ(s.advice[1].rfind("The camera moved 4.00 m around the subject; 3D photos are taken "
                              "from one spot: stand still and turn", 0),
            0u)
      << s.advice[1];
  // Without a metric model, the same as a multiple of the near depth.
  const CaptureShape u = MeasureCaptureShape(b.model(), b.Frame(), {}, false);
  ASSERT_GE(u.advice.size(), 2u);
  char moved[96];
  std::snprintf(moved, sizeof moved,
                "The camera moved %.2f times the distance to the nearest objects around the subject",
                u.extent / u.near_depth);
  EXPECT_EQ(u.advice[1].rfind(moved, 0), 0u) << u.advice[1];
  EXPECT_GT(u.extent / u.near_depth, 2.0);
}

TEST(CaptureShape, WalkAlongAFacadeIsSideways) {
  // 10 photos 1 m apart along a wall 4 m away, all looking at it.
  ModelBuilder b;
  for (int i = 0; i < 10; ++i) b.AddPhoto({i - 4.5, 0, 0}, -Eigen::Vector3d::UnitZ());
  std::vector<ScenePoint> wall;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-8, 8);
  for (int i = 0; i < 4000; ++i) wall.push_back({{u(rng), 0.4 * u(rng), -4.0}, Eigen::Vector3d::UnitZ()});
  b.AddPoints(wall);
  const CaptureShape s = MeasureCaptureShape(b.model(), b.Frame(), {}, true);
  EXPECT_NEAR(s.extent, 9.0, 1e-9);
  EXPECT_TRUE(s.walked);
  EXPECT_FALSE(s.around);
  ASSERT_GE(s.advice.size(), 2u);
  EXPECT_NE(s.advice[1].find("moved 9.00 m sideways"), std::string::npos) << s.advice[1];
  // They all look the same way, too.
  EXPECT_TRUE(s.narrow);
}

TEST(CaptureShape, DisconnectedGroupAndUnplacedPhotosAreNamed) {
  ModelBuilder b = TurningCapture();  // img_00 .. img_15.
  // img_16 .. img_18 look backwards at a wall of their own: they share
  // nothing with the others.
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d d = Direction(170.0 + 10.0 * i, 0.0);
    b.AddPhoto(0.3 * d, d);
  }
  b.AddPoints(BackWall());
  const CaptureShape s =
      MeasureCaptureShape(b.model(), b.Frame(), {"img_19.jpg", "img_20.jpg"}, true);
  EXPECT_EQ(s.num_photos, 21);
  EXPECT_EQ(s.num_registered, 19);
  ASSERT_EQ(s.groups.size(), 2u);
  EXPECT_EQ(s.groups[0].size(), 16u);
  EXPECT_EQ(s.groups[1], (std::vector<std::string>{"img_16.jpg", "img_17.jpg", "img_18.jpg"}));
  EXPECT_TRUE(s.warning());
  const auto has = [&](const std::string& text) {
    for (const std::string& a : s.advice)
      if (a.find(text) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(has("Photos img_16.jpg-img_18.jpg overlap nothing the other photos saw"));
  EXPECT_TRUE(has("Photos img_19.jpg-img_20.jpg overlap nothing the other photos saw and were left out"));
  const nlohmann::json j = CaptureShapeJson(s);
  EXPECT_EQ(j["groups"].size(), 2u);
  EXPECT_EQ(j["groups"][1]["shared_points_with_largest"], 0);
  EXPECT_EQ(j["unregistered"].size(), 2u);
  EXPECT_TRUE(j["warning"].get<bool>());
}

TEST(CaptureShape, WeakLinkIsCountedAndNamed) {
  // One photo looking backwards at a wall of its own, which shares 10
  // points with img_00 (too few for a link).
  ModelBuilder b = TurningCapture();
  const Eigen::Vector3d d = Direction(180.0, 0.0);
  b.AddPhoto(0.3 * d, d);  // img_16.
  b.AddPoints(BackWall());
  b.AddSharedPoints(10, {1, 17});
  const CaptureShape s = MeasureCaptureShape(b.model(), b.Frame(), {}, true);
  ASSERT_EQ(s.groups.size(), 2u);
  EXPECT_EQ(s.groups[1], std::vector<std::string>{"img_16.jpg"});
  EXPECT_EQ(s.group_links, std::vector<int>{10});
  bool named = false;
  for (const std::string& a : s.advice)
    named |= a.rfind("Photo img_16.jpg is tied to the other photos by only 10 shared points: take "
                     "it with more overlap",
                     0) == 0;
  EXPECT_TRUE(named);
  // With 40 shared points (above min_link_points, and 5% of either photo's)
  // it belongs to the capture.
  b.AddSharedPoints(30, {1, 17});
  EXPECT_EQ(MeasureCaptureShape(b.model(), b.Frame(), {}, true).groups.size(), 1u);
}

TEST(CaptureShape, CameraSpreadIsTheFarthestCentre) {
  const ModelBuilder b = TurningCapture();
  std::vector<CoverageView> views;
  for (const auto& [id, image] : b.model().images) views.push_back({b.model().cameras.at(1), image.pose});
  PanoramaFrame frame;
  frame.centre[0] = 1.0;  // 1 m to the right of the rig.
  double farthest = 0.0;
  for (const CoverageView& v : views)
    farthest = std::max(farthest, (v.pose.Center() - Eigen::Vector3d(1, 0, 0)).norm());
  EXPECT_NEAR(CameraSpread(views, frame), farthest, 1e-12);
  EXPECT_EQ(CameraSpread({}, frame), 0.0);
}

TEST(NameRuns, ConsecutiveNamesBecomeRanges) {
  const std::vector<std::string> order = {"a", "b", "c", "d", "e", "f", "g"};
  EXPECT_EQ(NameRuns({"c"}, order), "c");
  EXPECT_EQ(NameRuns({"d", "b", "c"}, order), "b-d");
  EXPECT_EQ(NameRuns({"a", "c", "e", "f", "g"}, order), "a, c and e-g");
  EXPECT_EQ(NameRuns({"a", "x"}, order), "a and x");
}

TEST(CaptureShapeOptions, CheckNamesTheField) {
  CaptureShapeOptions o;
  EXPECT_TRUE(o.Check().ok());
  o.min_sweep = 0.5;
  EXPECT_EQ(o.Check().message(), "min_sweep 0.5 outside [1, 100]");
  EXPECT_THROW(MeasureCaptureShape(geometry::SparseModel(), PanoramaFrame(), {}, true, o),
               std::invalid_argument);
}

TEST(CaptureShapeOptions, EveryFieldIsDescribed) {
  util::testing::ExpectEveryFieldDescribed<CaptureShapeOptions>();
}

}  // namespace
}  // namespace casual3d::pipeline
