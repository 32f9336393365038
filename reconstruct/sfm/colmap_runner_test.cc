#include "reconstruct/sfm/colmap_runner.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include <gtest/gtest.h>


namespace casual3d::sfm {
namespace {

TEST(ParseColmapProgressTest, UnderstandsColmapLogLines) {
  long done = 0, total = 0;
  EXPECT_TRUE(ParseColmapProgress("I1123 15:20:01.1 feature_extraction.cc:247] Processed file [3/20]",
                                  20, &done, &total));
  EXPECT_EQ(done, 3);
  EXPECT_EQ(total, 20);
  EXPECT_TRUE(ParseColmapProgress("Matching block [2/3, 1/3]", 0, &done, &total));
  EXPECT_EQ(done, 4);
  EXPECT_EQ(total, 9);
  EXPECT_TRUE(ParseColmapProgress("Matching image [7/40] in 0.5s", 0, &done, &total));
  EXPECT_EQ(done, 7);
  EXPECT_EQ(total, 40);
  EXPECT_TRUE(ParseColmapProgress("Registering image #12 (5)", 16, &done, &total));
  EXPECT_EQ(done, 5);
  EXPECT_EQ(total, 16);
  EXPECT_TRUE(ParseColmapProgress("Undistorting image [16/16]", 0, &done, &total));
  EXPECT_EQ(done, 16);
  EXPECT_FALSE(ParseColmapProgress("Elapsed time: 0.1 [minutes]", 16, &done, &total));
  EXPECT_FALSE(ParseColmapProgress("Registering image #12 (5)", 0, &done, &total));
}

class RunColmapTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "/colmap_runner_" + std::to_string(::getpid());
    ::mkdir(dir_.c_str(), 0755);
  }
  // A stand-in `colmap` program: a shell script with `body`.
  std::string FakeColmap(const std::string& body) {
    const std::string path = dir_ + "/colmap";
    std::ofstream(path) << "#!/bin/sh\n" << body << "\n";
    ::chmod(path.c_str(), 0755);
    return path;
  }
  std::string dir_;
};

TEST_F(RunColmapTest, CapturesLinesExitStatusAndSignals) {
  const std::string colmap = FakeColmap(
      "echo \"cmd $1 $2\"; echo 'Processed file [1/2]' >&2; printf 'Processed file [2/2]'; "
      "exit 3");
  const std::string log = dir_ + "/log.txt";
  std::vector<std::string> lines;
  ColmapResult r = RunColmap(colmap, "feature_extractor", {"--x", "y"}, log,
                             [&](const std::string& l) { lines.push_back(l); });
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.signal, 0);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "cmd feature_extractor --x");
  EXPECT_EQ(lines[2], "Processed file [2/2]");  // Last line without a newline.
  EXPECT_EQ(DescribeExit(r), "exit status 3");
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("feature_extractor --x y"), std::string::npos);
  EXPECT_NE(text.find("Processed file [1/2]"), std::string::npos);

  r = RunColmap(FakeColmap("kill -9 $$"), "mapper", {}, log, nullptr);
  EXPECT_EQ(r.signal, 9);
  EXPECT_NE(DescribeExit(r).find("signal 9"), std::string::npos);
}

TEST_F(RunColmapTest, FindColmapExplainsHowToInstall) {
  try {
    FindColmap(dir_ + "/no-such-colmap");
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("apt-get install colmap"), std::string::npos);
  }
  const std::string fake = FakeColmap("exit 0");
  EXPECT_EQ(FindColmap(fake), fake);
}

}  // namespace
}  // namespace casual3d::sfm
