// `casual3d encode`, `info` and `validate` as a user runs them: exit codes, the
// files they write, and one clear error line on bad input.

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "encoder/master_file.h"
#include "format/package_test_scene.h"

namespace casual3d {
namespace {

namespace fs = std::filesystem;

struct CommandResult {
  int exit_code;
  std::string output;  // stdout and stderr.
};

CommandResult Casual3d(const std::string& args) {
  const char* bin = std::getenv("CASUAL3D_BINARY_DIR");
  const std::string cmd = std::string(bin != nullptr ? bin : ".") + "/cli/casual3d " + args + " 2>&1";
  CommandResult run{-1, ""};
  FILE* pipe = popen(cmd.c_str(), "r");
  if (pipe == nullptr) return run;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), pipe)) > 0) run.output.append(buf, n);
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

class PackageCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* bin = std::getenv("CASUAL3D_BINARY_DIR");
    if (bin == nullptr || !fs::exists(fs::path(bin) / "cli/casual3d"))
      GTEST_SKIP() << "the casual3d program is not built";
    dir_ = fs::temp_directory_path() / ("casual3d_package_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    master_ = (dir_ / "master.exr").string();
    ASSERT_TRUE(encoder::WriteMasterFile(testing::MakePackageTestPanorama(256, 128), master_).ok());
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  std::string master_;
};

TEST_F(PackageCliTest, ViewHintsGoFromTheMasterFileToThePackage) {
  TwoLayerPanorama pano = testing::MakePackageTestPanorama(256, 128);
  ViewHints hints;
  hints.yaw_deg = 12.5;
  hints.fov_deg = 48.0;
  hints.content_yaw_min_deg = -40.0;
  hints.content_yaw_max_deg = 60.0;
  hints.content_pitch_min_deg = -30.0;
  hints.content_pitch_max_deg = 35.0;
  hints.volume_radius = 0.07;
  pano.view_hints() = hints;
  const std::string master = (dir_ / "hinted.exr").string(), pkg = (dir_ / "hinted").string();
  ASSERT_TRUE(encoder::WriteMasterFile(pano, master).ok());
  CommandResult encode = Casual3d("encode " + master + " -o " + pkg + " --no-viewer");
  ASSERT_EQ(encode.exit_code, 0) << encode.output;
  CommandResult info = Casual3d("info " + pkg);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("casual3d 1.1"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("normals      octahedral, 5 bits per coordinate"), std::string::npos)
      << info.output;
  EXPECT_NE(info.output.find("opens at yaw 12.5, pitch 0.0, field of view 48.0 deg"),
            std::string::npos) << info.output;
  EXPECT_NE(info.output.find("radius 0.07 (the capture's units)"), std::string::npos) << info.output;
  CommandResult validate = Casual3d("validate " + pkg);
  EXPECT_EQ(validate.exit_code, 0) << validate.output;
  EXPECT_NE(validate.output.find("valid casual3d 1.1 package"), std::string::npos) << validate.output;
  // Lossy normals make it 1.2, and say their bounds.
  const std::string lossy = (dir_ / "lossy").string();
  CommandResult encode_lossy = Casual3d("encode " + master + " -o " + lossy +
                                        " --no-viewer --lossy-normals --normal-p99-error 7");
  ASSERT_EQ(encode_lossy.exit_code, 0) << encode_lossy.output;
  info = Casual3d("info " + lossy);
  EXPECT_NE(info.output.find("casual3d 1.2"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("normals      octahedral, lossy: per tile mean error at most 2.5, "
                             "99th percentile at most 7 degrees"),
            std::string::npos)
      << info.output;
  validate = Casual3d("validate " + lossy);
  EXPECT_EQ(validate.exit_code, 0) << validate.output;
  EXPECT_NE(validate.output.find("valid casual3d 1.2 package"), std::string::npos) << validate.output;
  // A bound out of range: one line naming the flag, exit 1.
  CommandResult bad = Casual3d("encode " + master + " -o " + (dir_ / "bad").string() +
                               " --lossy-normals --normal-mean-error 0.5");
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("--normal-mean-error"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
  CommandResult plain = Casual3d("encode " + master_ + " -o " + (dir_ / "plain").string() +
                                 " --no-viewer");
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  info = Casual3d("info " + (dir_ / "plain").string());
  EXPECT_NE(info.output.find("casual3d 1.0"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("view         none: viewers choose"), std::string::npos) << info.output;
}

TEST_F(PackageCliTest, EncodeInfoValidate) {
  const std::string pkg = (dir_ / "pkg").string(), c3d = (dir_ / "pkg.c3d").string();
  CommandResult encode = Casual3d("encode " + master_ + " -o " + pkg + " --tile-size 64 --levels 3 "
                        "--no-viewer --single-file " + c3d);
  ASSERT_EQ(encode.exit_code, 0) << encode.output;
  EXPECT_TRUE(fs::exists(fs::path(pkg) / "manifest.json"));
  EXPECT_TRUE(fs::exists(fs::path(pkg) / "l0/1-3.graph.webp"));
  CommandResult info = Casual3d("info " + c3d);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("level 2      64x32, 1x1 tiles"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("tiles        64 px, WebP images (image/webp)"), std::string::npos)
      << info.output;
  for (const std::string& p : {pkg, c3d}) {
    CommandResult validate = Casual3d("validate " + p);
    EXPECT_EQ(validate.exit_code, 0) << validate.output;
    EXPECT_NE(validate.output.find("valid casual3d 1.0 package"), std::string::npos);
  }
  // A corrupted tile: exit 1, one line naming the file.
  {
    std::fstream f(fs::path(pkg) / "l1/0-1.depth.webp", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(30);
    f.put('\x7f');
  }
  CommandResult bad = Casual3d("validate " + pkg);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find("casual3d: error: "), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("l1/0-1.depth.webp: SHA-256 does not match"), std::string::npos)
      << bad.output;
}

TEST_F(PackageCliTest, MaxKbFitsThePackageInItsBudget) {
  const std::string full = (dir_ / "full").string(), fitted = (dir_ / "fitted").string();
  ASSERT_EQ(Casual3d("encode " + master_ + " -o " + full + " --no-viewer").exit_code, 0);
  const auto package_bytes = [](const std::string& dir) {
    uintmax_t total = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir))
      if (e.is_regular_file()) total += e.file_size();
    return total;
  };
  const uintmax_t budget = package_bytes(full) * 9 / 10;
  CommandResult fit = Casual3d("-v encode " + master_ + " -o " + fitted + " --no-viewer --max-kb " +
                               std::to_string(budget / 1024));
  ASSERT_EQ(fit.exit_code, 0) << fit.output;
  EXPECT_NE(fit.output.find("--max-kb " + std::to_string(budget / 1024) + ": fitted with"), std::string::npos)
      << fit.output;
  EXPECT_LE(package_bytes(fitted), budget / 1024 * 1024);
  EXPECT_EQ(Casual3d("validate " + fitted).exit_code, 0);
}

TEST_F(PackageCliTest, BadInputsGiveOneClearLine) {
  struct Case {
    std::string args, message;
  } cases[] = {
      {"encode " + (dir_ / "missing.exr").string() + " -o " + (dir_ / "out").string(),
       "missing.exr: no such master file"},
      {"encode " + master_ + " -o " + (dir_ / "out").string() + " --tile-size 9",
       "--tile-size: 9 is outside [16, 4096]"},
      {"encode " + master_ + " -o " + (dir_ / "out").string() + " --levels 9",
       "--levels: 9 is outside 0 or [1, 8]"},
      {"encode " + master_ + " -o " + (dir_ / "out").string() + " --quality 101",
       "--quality: 101 is outside [0, 100]"},
      {"encode " + master_ + " -o " + dir_.string(), "is not a casual3d package"},
      {"encode " + master_ + " -o " + (dir_ / "out").string() + " --max-kb 1",
       "the package does not fit in 1.0 KB: the smallest was"},
      {"encode " + master_ + " -o " + (dir_ / "out").string() + " --max-kb -3",
       "--max-kb: -3 is outside >= 0"},
      {"encode " + master_ + " -o " + (dir_ / "out").string() + " --max-kb 100 --min-quality 120",
       "--min-quality: 120 is outside [0, 100]"},
      {"info " + master_, "not a package folder (no manifest.json) nor a valid .c3d file"},
      {"validate " + (dir_ / "nothing").string(), "not a package folder"},
  };
  for (const Case& c : cases) {
    CommandResult run = Casual3d(c.args);
    EXPECT_EQ(run.exit_code, 1) << c.args << "\n" << run.output;
    EXPECT_NE(run.output.find("casual3d: error: "), std::string::npos) << run.output;
    EXPECT_NE(run.output.find(c.message), std::string::npos) << c.args << "\n" << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  }
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  EXPECT_TRUE(fs::exists(master_));
}

}  // namespace
}  // namespace casual3d
