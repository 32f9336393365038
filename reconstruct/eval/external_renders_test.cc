#include "reconstruct/eval/external_renders.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "reconstruct/io/image_io.h"

namespace casual3d::eval {
namespace {

render::PinholeView TestView() {
  render::PinholeView v;
  v.width = 640;
  v.height = 480;
  v.fx = 500;
  v.fy = 520;
  v.cx = 300;
  v.cy = 250;
  v.rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1, 0.1).normalized()).toRotationMatrix();
  v.translation = Eigen::Vector3d(0.1, -0.2, 0.05);
  return v;
}

TEST(GlMatricesTest, ProjectToTheSamePixelAsThePinholeView) {
  const render::PinholeView v = TestView();
  double vm[16], pm[16];
  GlMatrices(v, 0.05, 100.0, vm, pm);
  const Eigen::Matrix4d view = Eigen::Map<const Eigen::Matrix4d>(vm);  // column-major
  const Eigen::Matrix4d proj = Eigen::Map<const Eigen::Matrix4d>(pm);
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.3, 0.2, 3.0), Eigen::Vector3d(-1, 0.5, 7),
                                   Eigen::Vector3d(0.8, -0.6, 2)}) {
    const Eigen::Vector3d c = v.rotation * p + v.translation;
    ASSERT_GT(c.z(), 0);
    const double u = v.fx * c.x() / c.z() + v.cx, w = v.fy * c.y() / c.z() + v.cy;
    const Eigen::Vector4d clip = proj * view * p.homogeneous();
    const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
    EXPECT_NEAR((ndc.x() + 1) / 2 * v.width, u, 1e-9);
    EXPECT_NEAR((1 - ndc.y()) / 2 * v.height, w, 1e-9);
    EXPECT_GT(ndc.z(), -1);
    EXPECT_LT(ndc.z(), 1);
    // The eye frame looks along -Z.
    EXPECT_NEAR((view * p.homogeneous()).z(), -c.z(), 1e-12);
  }
}

TEST(RephotoCamerasJsonTest, NamesImagesAndRefusesBadClipPlanes) {
  const std::string text = RephotoCamerasJson({{"dir/IMG_1.JPG", TestView()}}, 0.05, 10);
  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_EQ(j["format"], "casual3d-rephoto-cameras");
  EXPECT_EQ(j["cameras"][0]["image"], "dir_IMG_1.png");
  EXPECT_EQ(j["cameras"][0]["view_matrix"].size(), 16u);
  EXPECT_THROW(RephotoCamerasJson({{"a.jpg", TestView()}}, 1, 1), std::invalid_argument);
}

TEST(ReadRephotoCamerasTest, ReadsBackWhatRephotoCamerasJsonWrote) {
  const auto dir = std::filesystem::temp_directory_path() / "casual3d_read_rephoto_cameras_test";
  std::filesystem::create_directories(dir);
  render::PinholeView other = TestView();
  other.width = 64;
  other.cx = 30;
  other.translation = Eigen::Vector3d(0.5, -1, 2);
  const std::string path = (dir / "cams.json").string();
  std::ofstream(path) << RephotoCamerasJson({{"b.jpg", TestView()}, {"a.jpg", other}}, 0.05, 10);
  const std::vector<NamedView> read = ReadRephotoCameras(path);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].name, "b.jpg");
  EXPECT_EQ(read[1].name, "a.jpg");
  for (int k = 0; k < 2; ++k) {
    const render::PinholeView& want = k == 0 ? TestView() : other;
    const render::PinholeView& got = read[k].view;
    EXPECT_EQ(got.width, want.width);
    EXPECT_EQ(got.height, want.height);
    EXPECT_DOUBLE_EQ(got.fx, want.fx);
    EXPECT_DOUBLE_EQ(got.cx, want.cx);
    EXPECT_LT((got.rotation - want.rotation).norm(), 1e-12);
    EXPECT_LT((got.translation - want.translation).norm(), 1e-12);
  }
  // Not such a document: the file is named.
  std::ofstream(path) << "{\"cameras\": [";
  try {
    ReadRephotoCameras(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadRephotoCameras((dir / "missing.json").string()), std::runtime_error);
  std::filesystem::remove_all(dir);
}

TEST(ReadExternalRenderTest, AlphaIsCoverageAndSizeIsChecked) {
  const auto dir = std::filesystem::temp_directory_path() / "casual3d_external_renders_test";
  std::filesystem::create_directories(dir);
  Image8 rgb(4, 3, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x)
      for (int k = 0; k < 3; ++k) rgb.at(x, y, k) = static_cast<uint8_t>(10 * x + y + 100 * k);
  io::WritePng((dir / "a.png").string(), rgb);
  const ExternalRender r = ReadExternalRender(dir.string(), "a.jpg", 4, 3);
  EXPECT_EQ(r.color.at(3, 2, 2), 232);
  EXPECT_EQ(r.mask.at(1, 1), 255);
  EXPECT_THROW(ReadExternalRender(dir.string(), "a.jpg", 5, 3), std::runtime_error);
  EXPECT_THROW(ReadExternalRender(dir.string(), "b.jpg", 4, 3), std::runtime_error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace casual3d::eval
