#include "reconstruct/sfm/reference_poses.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>

namespace casual3d::sfm {
namespace {

std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "/reference_poses_" + std::to_string(::getpid()) + "_" + name;
}

// Writes a version 1.0 .npy file of float64 (or float32) values.
void WriteNpy(const std::string& path, const std::string& shape, const std::vector<double>& values,
              bool float32 = false, const char* descr = nullptr) {
  std::string header = std::string("{'descr': '") + (descr ? descr : (float32 ? "<f4" : "<f8")) +
                       "', 'fortran_order': False, 'shape': " + shape + ", }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  out.write("\x93NUMPY\x01\x00", 8);
  const uint16_t len = static_cast<uint16_t>(header.size());
  out.put(static_cast<char>(len & 0xff));
  out.put(static_cast<char>(len >> 8));
  out << header;
  for (double v : values) {
    if (float32) {
      const float f = static_cast<float>(v);
      out.write(reinterpret_cast<const char*>(&f), 4);
    } else {
      out.write(reinterpret_cast<const char*>(&v), 8);
    }
  }
}

Eigen::Matrix3d RandomRotation(std::mt19937* rng) {
  std::normal_distribution<double> n(0, 1);
  return Eigen::Quaterniond(n(*rng), n(*rng), n(*rng), n(*rng)).normalized().toRotationMatrix();
}

TEST(NpyTest, ReadsFloat64AndFloat32) {
  const std::string path = TempPath("a.npy");
  WriteNpy(path, "(2, 3)", {1, 2, 3, 4, 5, 6.5});
  NpyArray a = ReadNpy(path);
  ASSERT_EQ(a.shape, (std::vector<size_t>{2, 3}));
  EXPECT_DOUBLE_EQ(a.data[5], 6.5);
  WriteNpy(path, "(4,)", {0.25, -1, 3, 1e6}, true);
  a = ReadNpy(path);
  ASSERT_EQ(a.shape, (std::vector<size_t>{4}));
  EXPECT_FLOAT_EQ(static_cast<float>(a.data[3]), 1e6f);
  std::remove(path.c_str());
}

TEST(NpyTest, RejectsBadFiles) {
  const std::string path = TempPath("bad.npy");
  WriteNpy(path, "(2, 3)", {1, 2, 3});  // Truncated data.
  EXPECT_THROW(ReadNpy(path), std::runtime_error);
  WriteNpy(path, "(2,)", {1, 2}, false, ">f8");  // Big-endian.
  EXPECT_THROW(ReadNpy(path), std::runtime_error);
  WriteNpy(path, "(2,)", {1, 2}, false, "<i8");  // Integers.
  EXPECT_THROW(ReadNpy(path), std::runtime_error);
  std::ofstream(path) << "not numpy";
  try {
    ReadNpy(path);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad magic"), std::string::npos);
  }
  std::remove(path.c_str());
}

TEST(LlffTest, ConvertsAxesToColmapConvention) {
  // A camera at C looking along world +X with image up = world +Z.
  // COLMAP axes in world: right = -Y, down = -Z, forward = +X.
  // LLFF columns: down, right, back.
  const Eigen::Vector3d C(1, 2, 3);
  const Eigen::Vector3d right(0, -1, 0), down(0, 0, -1), forward(1, 0, 0);
  std::vector<double> row;
  for (int r = 0; r < 3; ++r) {
    row.insert(row.end(), {down[r], right[r], -forward[r], C[r]});
    row.push_back(r == 0 ? 756 : (r == 1 ? 1008 : 815.5));  // h, w, f.
  }
  row.push_back(1.5);  // near
  row.push_back(90);   // far
  std::vector<double> values = row;
  values.insert(values.end(), row.begin(), row.end());
  const std::string path = TempPath("poses_bounds.npy");
  WriteNpy(path, "(2, 17)", values);
  const auto cams = ReadLlffPosesBounds(path, {"a.jpg", "b.jpg"});
  ASSERT_EQ(cams.size(), 2u);
  const ReferenceCamera& cam = cams.at("a.jpg");
  EXPECT_EQ(cam.width, 1008);
  EXPECT_EQ(cam.height, 756);
  EXPECT_DOUBLE_EQ(cam.focal_px, 815.5);
  EXPECT_LT((cam.pose.Center() - C).norm(), 1e-12);
  // A point ahead of the camera and to its right projects to +Z, +X.
  const Eigen::Vector3d p = cam.pose.WorldToCamera(C + 2 * forward + 0.5 * right);
  EXPECT_NEAR(p.z(), 2.0, 1e-12);
  EXPECT_NEAR(p.x(), 0.5, 1e-12);
  EXPECT_NEAR(p.y(), 0.0, 1e-12);
  EXPECT_THROW(ReadLlffPosesBounds(path, {"a.jpg"}), std::runtime_error);
  std::remove(path.c_str());
}

TEST(StrechaTest, ReadsCameraFile) {
  // Camera-to-world R with columns = camera axes; camera looks along world -Y.
  const std::string path = TempPath("0000.jpg.camera");
  std::ofstream(path) << "2759.48 0 1520.69\n0 2764.16 1006.81\n0 0 1\n0 0 0\n"
                         "1 0 0\n0 0 -1\n0 1 0\n"
                         "-7.5 -7.25 0.25\n3072 2048\n";
  const ReferenceCamera cam = ReadStrechaCamera(path);
  EXPECT_EQ(cam.width, 3072);
  EXPECT_EQ(cam.height, 2048);
  EXPECT_DOUBLE_EQ(cam.focal_px, 2759.48);
  EXPECT_LT((cam.pose.Center() - Eigen::Vector3d(-7.5, -7.25, 0.25)).norm(), 1e-12);
  // Camera +Z is the third column of R: world (0, -1, 0).
  EXPECT_LT((cam.pose.ViewingDirection() - Eigen::Vector3d(0, -1, 0)).norm(), 1e-12);
  std::ofstream(path) << "1 2 3\n";
  EXPECT_THROW(ReadStrechaCamera(path), std::runtime_error);
  std::ofstream(path) << "1 0 0 0 1 0 0 0 1 0 0 0 1 0 0 0 1 0 0 0 2 0 0 0 10 10\n";
  EXPECT_THROW(ReadStrechaCamera(path), std::runtime_error);  // Not a rotation.
  std::remove(path.c_str());
}

TEST(ComparePosesTest, RecoversSimilarityAndMeasuresErrors) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::map<std::string, geometry::Pose> reference, estimated;
  geometry::Similarity3 sim;  // Maps the reference into the estimate's world.
  sim.scale = 0.37;
  sim.R = RandomRotation(&rng);
  sim.t = Eigen::Vector3d(4, -2, 9);
  for (int i = 0; i < 12; ++i) {
    const std::string name = "p" + std::to_string(i);
    const Eigen::Matrix3d R = RandomRotation(&rng);
    const Eigen::Vector3d centre(u(rng) * 3, u(rng), u(rng) * 2);
    reference[name] = geometry::Pose::FromCenter(R, centre);
    estimated[name] = sim.ApplyToPose(reference[name]);
  }
  reference["only_in_reference"] = reference["p0"];
  PoseComparison c = ComparePoses(estimated, reference);
  EXPECT_EQ(c.num_common, 12);
  EXPECT_LT(c.max_rotation_error_deg, 1e-6);
  EXPECT_LT(c.max_centre_error, 1e-9);
  EXPECT_NEAR(c.alignment.scale, 1.0 / 0.37, 1e-9);
  EXPECT_GT(c.reference_spread, 1.0);

  // Rotate one estimated camera by 2 degrees about its axis: max error 2, mean 2/12.
  geometry::Pose& p = estimated["p5"];
  p.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(2.0 * M_PI / 180, Eigen::Vector3d::UnitZ())) *
               p.rotation;
  p.translation = -(p.rotation.toRotationMatrix() *
                    sim.Apply(reference["p5"].Center()));  // Same centre.
  c = ComparePoses(estimated, reference);
  // The mean rotation moves by about 2/12 degree towards the odd camera: it is
  // off by 2 - 2/12, the 11 others by 2/12 each.
  EXPECT_NEAR(c.max_rotation_error_deg, 2.0 - 2.0 / 12, 0.01);
  EXPECT_NEAR(c.mean_rotation_error_deg, (2.0 - 2.0 / 12 + 11 * 2.0 / 12) / 12, 0.01);
  EXPECT_LT(c.max_centre_error, 0.01);

  std::map<std::string, geometry::Pose> two = {{"p0", estimated["p0"]}, {"p1", estimated["p1"]}};
  EXPECT_THROW(ComparePoses(two, reference), std::runtime_error);
}

}  // namespace
}  // namespace casual3d::sfm
