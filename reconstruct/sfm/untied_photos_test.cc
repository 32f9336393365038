#include "reconstruct/sfm/untied_photos.h"

#include <gtest/gtest.h>

namespace casual3d::sfm {
namespace {

// Three photos seeing 20 shared points, a fourth seeing 2 of them and 1 point
// that only it and the first photo see.
geometry::SparseModel Model() {
  geometry::SparseModel m;
  for (int id = 1; id <= 4; ++id) {
    geometry::ModelImage image;
    image.image_id = id;
    image.camera_id = 1;
    image.name = "frame_00000" + std::to_string(id) + ".jpg";
    m.images[id] = image;
  }
  const auto observe = [&](uint64_t point, int image) {
    geometry::ModelImage& im = m.images.at(image);
    m.points[point].point3d_id = point;
    m.points[point].track.push_back({image, static_cast<int>(im.points2d.size())});
    geometry::Observation2D o;
    o.point3d_id = point;
    im.points2d.push_back(o);
  };
  for (uint64_t p = 1; p <= 20; ++p)
    for (int image = 1; image <= 3; ++image) observe(p, image);
  observe(1, 4);
  observe(2, 4);
  observe(21, 1);
  observe(21, 4);
  return m;
}

TEST(UntiedPhotosTest, PhotosSeeingFewPointsAreLeftOut) {
  geometry::SparseModel m = Model();
  const std::vector<UntiedPhoto> dropped = DropUntiedPhotos(15, &m);
  ASSERT_EQ(dropped.size(), 1u);
  EXPECT_EQ(dropped[0].name, "frame_000004.jpg");
  EXPECT_EQ(dropped[0].points, 3);
  EXPECT_EQ(m.images.size(), 3u);
  // Its observations left the tracks; point 21, seen by one photo now, went,
  // and the first photo's reference to it is invalid.
  EXPECT_EQ(m.points.size(), 20u);
  EXPECT_EQ(m.points.at(1).track.size(), 3u);
  EXPECT_EQ(m.images.at(1).points2d.back().point3d_id, geometry::kInvalidPoint3DId);
  EXPECT_EQ(m.images.at(1).points2d.front().point3d_id, 1u);
}

TEST(UntiedPhotosTest, WellTiedModelsAreUnchanged) {
  geometry::SparseModel m = Model();
  EXPECT_TRUE(DropUntiedPhotos(3, &m).empty());
  EXPECT_EQ(m.images.size(), 4u);
  EXPECT_EQ(m.points.size(), 21u);
  EXPECT_TRUE(DropUntiedPhotos(0, &m).empty());
}

}  // namespace
}  // namespace casual3d::sfm
