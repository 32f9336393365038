// The capture's advice (reconstruct/pipeline/capture_shape.h) through the
// `casual3d` program: a synthetic walk-around capture is told, in the log and
// in report.json, that the camera moved around the subject and by how much;
// the default synthetic capture (turning on the spot) gets no warning. Runs
// COLMAP twice on 640x480 photos (under a minute on 2 cores).

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "reconstruct/io/file_util.h"
#include "tests/casual3d_cli.h"

namespace casual3d {
namespace {

namespace fs = std::filesystem;

using testing::Casual3d;
using testing::CommandRun;

class CaptureAdviceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("capture_advice_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    for (const std::string rig : {"walk-around", "partial"}) {
      const CommandRun synth = Casual3d("synth --rig " + rig + " -o " + (root_ / rig).string() +
                                        " --width 640 --panorama-width 256 --threads 2");
      ASSERT_EQ(synth.exit_code, 0) << synth.output;
    }
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  // Reconstructs `input` up to the sparse stage; its report's "capture".
  // One thread: COLMAP's multi-threaded mapper can register a different set
  // of these small photos when the machine is loaded (once 11 of 16 under a
  // full parallel test run), and the advice depends on the registered photos.
  static nlohmann::json Capture(const fs::path& input, const std::string& out, std::string* log) {
    const CommandRun run = Casual3d("reconstruct " + input.string() + " -o " + (root_ / out).string() +
                                    " --to sparse --threads 1");
    EXPECT_EQ(run.exit_code, 0) << run.output;
    *log = run.output;
    const nlohmann::json report =
        nlohmann::json::parse(io::ReadFile((root_ / out / "report.json").string()));
    return report.value("capture", nlohmann::json());
  }
  static fs::path root_;
};
fs::path CaptureAdviceTest::root_;

TEST_F(CaptureAdviceTest, WalkAroundIsToldToStandStillAndTurn) {
  // Photos through COLMAP (model units): the distance as a multiple of the
  // near depth.
  std::string log;
  const nlohmann::json c = Capture(root_ / "walk-around" / "images", "walk", &log);
  ASSERT_TRUE(c.is_object());
  EXPECT_EQ(c["registered"], 12);
  EXPECT_EQ(c["unit"], "model");
  EXPECT_TRUE(c["walked"].get<bool>());
  EXPECT_TRUE(c["moved_around_subject"].get<bool>());
  EXPECT_TRUE(c["warning"].get<bool>());
  // The arc spans 90 degrees; the camera moved about its chord, 1.84 m,
  // beside objects from 0.6 m away.
  EXPECT_NEAR(c["axis_span_deg"].get<double>(), 90.0, 5.0);
  EXPECT_GT(c["off_axis_over_near"].get<double>(), 0.5);
  ASSERT_EQ(c["advice"].size(), 2u);
  const std::string advice = c["advice"][1];
  EXPECT_EQ(advice.rfind("The camera moved ", 0), 0u) << advice;
  EXPECT_NE(advice.find(" times the distance to the nearest objects around the subject; 3D photos are "
                        "taken from one spot: stand still and turn"),
            std::string::npos)
      << advice;
  EXPECT_NE(log.find("warning: capture: " + advice), std::string::npos) << log;

  // The same capture as a workspace (its ground-truth model, in metres):
  // the distance walked in metres.
  const nlohmann::json m = Capture(root_ / "walk-around", "walk_ws", &log);
  ASSERT_TRUE(m.is_object());
  EXPECT_EQ(m["unit"], "m");
  EXPECT_NEAR(m["extent"].get<double>(), 2 * 1.3 * std::sin(3.14159265358979 / 4), 0.05);
  ASSERT_EQ(m["advice"].size(), 2u);
  char expected[64];
  std::snprintf(expected, sizeof expected, "The camera moved %.2f m around the subject;",
                m["extent"].get<double>());
  EXPECT_EQ(m["advice"][1].get<std::string>().rfind(expected, 0), 0u) << m["advice"][1];
}

TEST_F(CaptureAdviceTest, DefaultCaptureGetsNoWarning) {
  std::string log;
  const nlohmann::json c = Capture(root_ / "partial" / "images", "partial", &log);
  ASSERT_TRUE(c.is_object());
  EXPECT_EQ(c["registered"], 16);
  EXPECT_TRUE(c["turned_about_a_point"].get<bool>());
  EXPECT_LT(c["off_axis_over_near"].get<double>(), 0.1);
  EXPECT_FALSE(c["walked"].get<bool>());
  EXPECT_FALSE(c["narrow"].get<bool>());
  EXPECT_EQ(c["groups"].size(), 1u);
  EXPECT_FALSE(c["warning"].get<bool>());
  ASSERT_EQ(c["advice"].size(), 1u);  // The description alone, printed.
  EXPECT_NE(log.find("capture: " + c["advice"][0].get<std::string>()), std::string::npos) << log;
  EXPECT_EQ(log.find("warning: capture"), std::string::npos) << log;
}

}  // namespace
}  // namespace casual3d
