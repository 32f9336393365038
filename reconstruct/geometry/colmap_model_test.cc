#include "reconstruct/geometry/colmap_model.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "base/testing/scratch_dir.h"

namespace casual3d::geometry {
namespace {

namespace fs = std::filesystem;

fs::path TempRoot() {
  return fs::temp_directory_path() / ("casual3d_colmap_model_test_" + std::to_string(::getpid()));
}

// Removes the test's temporary folders when the test program ends.
class TempRootCleaner : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(TempRoot(), ignored);
  }
};
const auto* const kCleaner = ::testing::AddGlobalTestEnvironment(new TempRootCleaner);

// A fresh, empty folder for one test.
std::string TempDir(const std::string& name) {
  const fs::path dir = TempRoot() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

using casual3d::testing::ReadWholeFile;
using casual3d::testing::WriteWholeFile;

// A small but complete model: three camera models, images with and without
// observations, points with tracks, values that need all 17 digits.
SparseModel MakeModel() {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  SparseModel model;
  Camera c1;
  c1.camera_id = 1;
  c1.model = CameraModelId::kSimpleRadial;
  c1.width = 4032;
  c1.height = 3024;
  c1.params = {3260.123456789012, 2016.5, 1512.25, 0.021345678901234};
  Camera c2;
  c2.camera_id = 7;
  c2.model = CameraModelId::kOpenCV;
  c2.width = 1000;
  c2.height = 750;
  c2.params = {810.1, 809.9, 500.3, 374.8, -0.04, 0.01, 1e-4, -2e-4};
  Camera c3;
  c3.camera_id = 3;
  c3.model = CameraModelId::kPinhole;
  c3.width = 640;
  c3.height = 480;
  c3.params = {500.0, 501.0, 320.0, 240.0};
  model.cameras = {{1, c1}, {7, c2}, {3, c3}};

  for (int id = 1; id <= 4; ++id) {
    ModelImage image;
    image.image_id = id * 10;
    image.camera_id = id == 2 ? 7 : (id == 4 ? 3 : 1);
    image.name = id == 3 ? "sub dir/IMG 0003.jpg" : "IMG_000" + std::to_string(id) + ".jpg";
    image.pose.rotation =
        Eigen::Quaterniond(uniform(rng), uniform(rng), uniform(rng), uniform(rng)).normalized();
    image.pose.translation = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)) * 3.0;
    const int num_points = id == 4 ? 0 : 5 * id;
    for (int k = 0; k < num_points; ++k) {
      Observation2D obs;
      obs.xy = Eigen::Vector2d(uniform(rng) * 1000 + 1000, uniform(rng) * 700 + 700);
      obs.point3d_id = k % 3 == 0 ? kInvalidPoint3DId : static_cast<uint64_t>(k + 100);
      image.points2d.push_back(obs);
    }
    model.images.emplace(image.image_id, image);
  }
  for (uint64_t id : {101ull, 102ull, 104ull, 105ull, 9000000000ull}) {
    Point3D point;
    point.point3d_id = id;
    point.xyz = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)) * 10.0;
    point.rgb[0] = static_cast<uint8_t>(id % 256);
    point.rgb[1] = 255;
    point.rgb[2] = 0;
    point.error = 0.25 + uniform(rng) * 0.1;
    point.track = {{10, static_cast<int>(id % 5)}, {20, 1}, {30, 14}};
    model.points.emplace(id, point);
  }
  return model;
}

void ExpectModelsEqual(const SparseModel& a, const SparseModel& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (const auto& [id, camera] : a.cameras) {
    const Camera& other = b.cameras.at(id);
    EXPECT_EQ(camera.model, other.model);
    EXPECT_EQ(camera.width, other.width);
    EXPECT_EQ(camera.height, other.height);
    EXPECT_EQ(camera.params, other.params);
  }
  ASSERT_EQ(a.images.size(), b.images.size());
  for (const auto& [id, image] : a.images) {
    const ModelImage& other = b.images.at(id);
    EXPECT_EQ(image.camera_id, other.camera_id);
    EXPECT_EQ(image.name, other.name);
    EXPECT_EQ(image.pose.rotation.coeffs(), other.pose.rotation.coeffs());
    EXPECT_EQ(image.pose.translation, other.pose.translation);
    ASSERT_EQ(image.points2d.size(), other.points2d.size());
    for (size_t k = 0; k < image.points2d.size(); ++k) {
      EXPECT_EQ(image.points2d[k].xy, other.points2d[k].xy);
      EXPECT_EQ(image.points2d[k].point3d_id, other.points2d[k].point3d_id);
    }
  }
  ASSERT_EQ(a.points.size(), b.points.size());
  for (const auto& [id, point] : a.points) {
    const Point3D& other = b.points.at(id);
    EXPECT_EQ(point.xyz, other.xyz);
    EXPECT_EQ(point.rgb[0], other.rgb[0]);
    EXPECT_EQ(point.rgb[1], other.rgb[1]);
    EXPECT_EQ(point.rgb[2], other.rgb[2]);
    EXPECT_EQ(point.error, other.error);
    ASSERT_EQ(point.track.size(), other.track.size());
    for (size_t k = 0; k < point.track.size(); ++k) {
      EXPECT_EQ(point.track[k].image_id, other.track[k].image_id);
      EXPECT_EQ(point.track[k].point2d_idx, other.track[k].point2d_idx);
    }
  }
}

// Expects `fn` to throw ModelError whose message is exactly `message`.
template <typename Fn>
void ExpectModelError(Fn fn, const std::string& message) {
  try {
    fn();
    ADD_FAILURE() << "no ModelError; expected: " << message;
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()), message);
  }
}

TEST(ColmapModelTest, TextBinaryTextRoundTripIsExact) {
  const std::string text1 = TempDir("text1"), bin = TempDir("bin"), text2 = TempDir("text2");
  const SparseModel model = MakeModel();
  WriteModelText(model, text1);
  const SparseModel from_text = ReadModelText(text1);
  ExpectModelsEqual(model, from_text);
  WriteModelBinary(from_text, bin);
  const SparseModel from_bin = ReadModelBinary(bin);
  ExpectModelsEqual(model, from_bin);
  WriteModelText(from_bin, text2);
  for (const char* name : {"cameras.txt", "images.txt", "points3D.txt"}) {
    EXPECT_EQ(ReadWholeFile(text1 + "/" + name), ReadWholeFile(text2 + "/" + name)) << name;
  }
  // ReadModel prefers binary; no temporary files are left behind.
  ExpectModelsEqual(model, ReadModel(bin));
  int num_files = 0;
  for (const auto& entry : fs::directory_iterator(bin)) {
    (void)entry;
    ++num_files;
  }
  EXPECT_EQ(num_files, 3);
}

TEST(ColmapModelTest, BinaryLayoutMatchesColmap) {
  // cameras.bin of one SIMPLE_PINHOLE camera: u64 count, u32 id, i32 model,
  // u64 width, u64 height, f64 params[3] = 8 + 4 + 4 + 8 + 8 + 24 bytes.
  SparseModel model;
  Camera camera;
  camera.camera_id = 5;
  camera.model = CameraModelId::kSimplePinhole;
  camera.width = 640;
  camera.height = 480;
  camera.params = {500.0, 320.0, 240.0};
  model.cameras[5] = camera;
  ModelImage image;
  image.image_id = 2;
  image.camera_id = 5;
  image.name = "a.jpg";
  image.points2d.push_back({Eigen::Vector2d(1.0, 2.0), kInvalidPoint3DId});
  model.images[2] = image;
  const std::string dir = TempDir("layout");
  WriteModelBinary(model, dir);
  const std::string cams = ReadWholeFile(dir + "/cameras.bin");
  ASSERT_EQ(cams.size(), 56u);
  EXPECT_EQ(cams.substr(0, 8), std::string("\x01\0\0\0\0\0\0\0", 8));
  EXPECT_EQ(cams.substr(8, 4), std::string("\x05\0\0\0", 4));
  EXPECT_EQ(cams.substr(12, 4), std::string("\0\0\0\0", 4));
  EXPECT_EQ(cams.substr(16, 8), std::string("\x80\x02\0\0\0\0\0\0", 8));  // 640
  // images.bin: 8 + (4 + 56 + 4 + 6 + 8 + 24) bytes; the point3D id is all ones.
  const std::string imgs = ReadWholeFile(dir + "/images.bin");
  ASSERT_EQ(imgs.size(), 8u + 4 + 56 + 4 + 6 + 8 + 24);
  EXPECT_EQ(imgs.substr(72, 6), std::string("a.jpg\0", 6));
  EXPECT_EQ(imgs.substr(imgs.size() - 8), std::string(8, '\xff'));
  EXPECT_EQ(ReadWholeFile(dir + "/points3D.bin"), std::string(8, '\0'));
}

TEST(ColmapModelTest, TextToleratesCommentsBlankLinesAndCrlf) {
  const std::string dir = TempDir("tolerant");
  WriteWholeFile(dir + "/cameras.txt",
            "# a comment\n\n   \n1 PINHOLE 640 480 500 500 320 240\r\n# trailing comment\n\n");
  WriteWholeFile(dir + "/images.txt",
            "# header\n\n"
            "1 1 0 0 0 0.5 0 -1 1 img one.png\n"
            "10.5 20.25 7 30 40 -1\n"
            "\n"
            "  2 2 0 0 0 0 0 0 1 b.png\n"
            "\n");
  WriteWholeFile(dir + "/points3D.txt", "\n# none\n7 1 2 3 255 128 0 0.5 1 0\n");
  const SparseModel model = ReadModelText(dir);
  ASSERT_EQ(model.cameras.size(), 1u);
  EXPECT_EQ(model.cameras.at(1).params, (std::vector<double>{500, 500, 320, 240}));
  ASSERT_EQ(model.images.size(), 2u);
  const ModelImage& one = model.images.at(1);
  EXPECT_EQ(one.name, "img one.png");
  ASSERT_EQ(one.points2d.size(), 2u);
  EXPECT_EQ(one.points2d[0].point3d_id, 7u);
  EXPECT_EQ(one.points2d[1].point3d_id, kInvalidPoint3DId);
  EXPECT_EQ(one.points2d[1].xy, Eigen::Vector2d(30, 40));
  // Quaternion (2, 0, 0, 0) is normalized to the identity.
  const ModelImage& two = model.images.at(2);
  EXPECT_DOUBLE_EQ(two.pose.rotation.w(), 1.0);
  EXPECT_TRUE(two.points2d.empty());
  EXPECT_EQ(model.FindImageByName("b.png"), &two);
  EXPECT_EQ(model.FindImageByName("missing.png"), nullptr);
  ASSERT_EQ(model.points.size(), 1u);
  EXPECT_EQ(model.points.at(7).rgb[1], 128);
  ASSERT_EQ(model.points.at(7).track.size(), 1u);
}

TEST(ColmapModelTest, RejectsMalformedText) {
  const std::string dir = TempDir("malformed");
  const std::string cams = dir + "/cameras.txt";
  struct Case {
    std::string contents;
    std::string message;
  };
  const Case camera_cases[] = {
      {"# c\n1 PINHOLE 640 480 500 500 320\n",
       cams + ":2: expected 4 parameters for PINHOLE, got 3"},
      {"1 FISHEYE 640 480 500 500 320 240\n",
       cams + ":1: expected a camera model (SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, "
              "OPENCV), got 'FISHEYE'"},
      {"\n\n1 PINHOLE 640x 480 500 500 320 240\n",
       cams + ":3: expected WIDTH (an integer from 0 to 1048576), got '640x'"},
      {"1 PINHOLE 640 480 500 abc 320 240\n",
       cams + ":1: expected a camera parameter (a finite number), got 'abc'"},
      {"1 PINHOLE 640\n",
       cams + ":1: expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[], got 3 fields"},
      {"1 PINHOLE 640 480 500 500 320 240\n1 PINHOLE 640 480 500 500 320 240\n",
       cams + ":2: duplicate CAMERA_ID 1"},
      {"1 PINHOLE 640 480 -500 500 320 240\n",
       cams + ":1: invalid camera: focal length is not positive"},
  };
  for (const Case& c : camera_cases) {
    WriteWholeFile(cams, c.contents);
    ExpectModelError([&] { ReadCamerasText(cams); }, c.message);
  }

  const std::string imgs = dir + "/images.txt";
  const Case image_cases[] = {
      {"1 1 0 0 0 0 0 0 1\n", imgs + ":1: expected NAME after CAMERA_ID"},
      {"1 1 0 0 0 0 0\n", imgs + ":1: expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME"},
      {"1 1 0 0 0 0 0 0 1 a.png\n1 2 3 4\n",
       imgs + ":2: expected POINTS2D as triples (X Y POINT3D_ID), got 4 values"},
      {"1 1 0 0 0 0 0 0 1 a.png\n1 2 -7\n",
       imgs +
           ":2: expected POINT3D_ID or -1 (an integer from 0 to 18446744073709551614), got '-7'"},
      {"1 0 0 0 0 0 0 0 1 a.png\n\n", imgs + ":1: expected a non-zero quaternion QW QX QY QZ"},
      {"1 1 0 0 0 0 0 nan 1 a.png\n\n", imgs + ":1: expected TZ (a finite number), got 'nan'"},
  };
  for (const Case& c : image_cases) {
    WriteWholeFile(imgs, c.contents);
    ExpectModelError([&] { ReadImagesText(imgs); }, c.message);
  }

  const std::string pts = dir + "/points3D.txt";
  const Case point_cases[] = {
      {"1 0 0 0 255 255 255 0.5 1\n",
       pts + ":1: expected POINT3D_ID X Y Z R G B ERROR followed by (IMAGE_ID POINT2D_IDX) pairs, "
             "got 9 fields"},
      {"1 0 0 0 256 255 255 0.5\n",
       pts + ":1: expected R, G or B (an integer from 0 to 255), got '256'"},
  };
  for (const Case& c : point_cases) {
    WriteWholeFile(pts, c.contents);
    ExpectModelError([&] { ReadPoints3DText(pts); }, c.message);
  }

  // An image referring to a camera that does not exist.
  WriteWholeFile(cams, "1 PINHOLE 640 480 500 500 320 240\n");
  WriteWholeFile(imgs, "4 1 0 0 0 0 0 0 9 x.png\n\n");
  WriteWholeFile(pts, "");
  ExpectModelError(
      [&] { ReadModelText(dir); },
      imgs + ": image 4 (x.png) refers to camera 9, which the cameras file does not define");

  ExpectModelError([&] { ReadCamerasText(dir + "/nope.txt"); },
                   dir + "/nope.txt: cannot open (No such file or directory)");
  const std::string empty = TempDir("empty");
  ExpectModelError([&] { ReadModel(empty); },
                   empty +
                       ": not a COLMAP sparse model (expected cameras, images and points3D as "
                       ".bin or .txt files; pass the folder that holds them, e.g. sparse/0)");
}

TEST(ColmapModelTest, RejectsMalformedBinary) {
  const std::string dir = TempDir("binary");
  WriteModelBinary(MakeModel(), dir);
  const std::string cams = dir + "/cameras.bin";
  const std::string good_cams = ReadWholeFile(cams);

  // Three cameras in 32 bytes cannot be: the count is rejected up front.
  WriteWholeFile(cams, good_cams.substr(0, 40));
  ExpectModelError([&] { ReadCamerasBinary(cams); },
                   cams +
                       ": offset 0: number of cameras 3 needs at least 24 bytes each but only "
                       "32 bytes remain");
  // One camera, truncated in the middle of its parameters.
  const std::string one_camera = std::string("\x01\0\0\0\0\0\0\0", 8) + good_cams.substr(8);
  WriteWholeFile(cams, one_camera.substr(0, 40));
  ExpectModelError([&] { ReadCamerasBinary(cams); },
                   cams +
                       ": offset 40: truncated: expected camera parameter (8 bytes) but the file "
                       "ends at 40");
  // An absurd count is rejected before anything is allocated.
  std::string huge = good_cams;
  huge.replace(0, 8, std::string("\xff\xff\xff\xff\xff\xff\xff\x7f", 8));
  WriteWholeFile(cams, huge);
  ExpectModelError([&] { ReadCamerasBinary(cams); },
                   cams +
                       ": offset 0: number of cameras 9223372036854775807 needs at least 24 "
                       "bytes each but only " +
                       std::to_string(good_cams.size() - 8) + " bytes remain");
  // Unknown model id.
  std::string bad_model = good_cams;
  bad_model[12] = 11;
  WriteWholeFile(cams, bad_model);
  ExpectModelError([&] { ReadCamerasBinary(cams); },
                   cams +
                       ": offset 12: expected a supported camera model id (0-4: SIMPLE_PINHOLE, "
                       "PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV), got 11");
  // Trailing garbage.
  WriteWholeFile(cams, good_cams + "xyz");
  ExpectModelError([&] { ReadCamerasBinary(cams); },
                   cams + ": offset " + std::to_string(good_cams.size()) +
                       ": unexpected trailing bytes after the last camera");
  WriteWholeFile(cams, "");
  ExpectModelError([&] { ReadCamerasBinary(cams); },
                   cams +
                       ": offset 0: truncated: expected number of cameras (8 bytes) but the "
                       "file ends at 0");

  // images.bin: a name without its terminating NUL, and a huge 2D point count.
  const std::string imgs = dir + "/images.bin";
  const std::string good_imgs = ReadWholeFile(imgs);
  const std::string one_image = std::string("\x01\0\0\0\0\0\0\0", 8) + good_imgs.substr(8);
  WriteWholeFile(imgs, one_image.substr(0, 8 + 4 + 56 + 4 + 9));
  ExpectModelError([&] { ReadImagesBinary(imgs); },
                   imgs +
                       ": offset 72: truncated: image name has no terminating NUL before the "
                       "end of the file");
  const size_t name_end = good_imgs.find('\0', 72);
  std::string many = good_imgs;
  many.replace(name_end + 1, 8, std::string("\0\0\0\0\0\0\0\x01", 8));
  WriteWholeFile(imgs, many);
  try {
    ReadImagesBinary(imgs);
    ADD_FAILURE() << "no error";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("number of 2D points 72057594037927936 needs at least 24 "
                                         "bytes each"),
              std::string::npos)
        << e.what();
  }

  // points3D.bin cut short in every possible place: always a ModelError.
  const std::string pts = dir + "/points3D.bin";
  const std::string good_pts = ReadWholeFile(pts);
  for (size_t size = 0; size < good_pts.size(); ++size) {
    WriteWholeFile(pts, good_pts.substr(0, size));
    EXPECT_THROW(ReadPoints3DBinary(pts), ModelError) << "size " << size;
  }
}

TEST(ColmapModelTest, CorruptedBinaryNeverCrashes) {
  // Random byte changes and truncations: every read either succeeds or throws
  // ModelError (no other exception, no crash, no huge allocation).
  const std::string dir = TempDir("corrupt");
  WriteModelBinary(MakeModel(), dir);
  std::mt19937 rng(5);
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const std::string path = dir + "/" + name;
    const std::string good = ReadWholeFile(path);
    int errors = 0;
    for (int trial = 0; trial < 300; ++trial) {
      std::string bad = good;
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < flips; ++k) {
        bad[rng() % bad.size()] = static_cast<char>(rng() % 256);
      }
      if (trial % 3 == 0) bad.resize(rng() % bad.size());
      WriteWholeFile(path, bad);
      try {
        if (name[0] == 'c') ReadCamerasBinary(path);
        if (name[0] == 'i') ReadImagesBinary(path);
        if (name[0] == 'p') ReadPoints3DBinary(path);
      } catch (const ModelError&) {
        ++errors;
      }
    }
    // Truncations always fail; most byte changes in counts, ids and model
    // numbers do too.
    EXPECT_GE(errors, 100) << name;
  }
}

TEST(ColmapModelTest, WriterReplacesExistingFiles) {
  const std::string dir = TempDir("replace");
  SparseModel model = MakeModel();
  WriteModelText(model, dir);
  model.points.clear();
  WriteModelText(model, dir);
  EXPECT_TRUE(ReadModelText(dir).points.empty());
  EXPECT_EQ(ReadWholeFile(dir + "/points3D.txt"),
            "# 3D point list with one line of data per point:\n"
            "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
            "# Number of points: 0, mean track length: 0\n");
}

TEST(ColmapModelTest, ReadsFernCameras) {
  const char* source = std::getenv("CASUAL3D_SOURCE_DIR");
  const fs::path path =
      fs::path(source ? source : ".") / ".." / "shared" / "datasets" / "fern" / "cameras.bin";
  if (!fs::exists(path)) {
    GTEST_SKIP() << "dataset not found at " << path.string()
                 << " (the shared datasets folder sits beside the source tree)";
  }
  const std::map<int, Camera> cameras = ReadCamerasBinary(path.string());
  ASSERT_EQ(cameras.size(), 1u);
  const Camera& camera = cameras.begin()->second;
  EXPECT_EQ(camera.model, CameraModelId::kSimpleRadial);
  EXPECT_TRUE(camera.IsValid());
  // The values COLMAP estimated for fern's iPhone X photos.
  EXPECT_EQ(camera.camera_id, 1);
  EXPECT_EQ(camera.width, 4032);
  EXPECT_EQ(camera.height, 3024);
  EXPECT_NEAR(camera.FocalX(), 3260.526, 1e-3);
  EXPECT_DOUBLE_EQ(camera.PrincipalX(), 2016.0);
  EXPECT_DOUBLE_EQ(camera.PrincipalY(), 1512.0);
  EXPECT_NEAR(camera.params[3], 0.0197505, 1e-7);
  EXPECT_NEAR(camera.FovXDeg(), 63.46, 0.01);
}

}  // namespace
}  // namespace casual3d::geometry
