#include "cli/viewer_assets.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "base/testing/scratch_dir.h"

namespace casual3d::cli {
namespace {
namespace fs = std::filesystem;

using casual3d::testing::ReadWholeFile;
using casual3d::testing::WriteWholeFile;

class ViewerAssetsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("casual3d_viewer_assets_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "viewer");
    fs::create_directories(root_ / "package");
    WriteWholeFile(root_ / "viewer" / "casual3d-viewer.js", "export {};\n");
    WriteWholeFile(root_ / "viewer" / "casual3d-format.wasm", std::string("\0asm\1\0\0\0", 8));
    setenv("CASUAL3D_VIEWER_DIR", (root_ / "viewer").c_str(), 1);
  }
  void TearDown() override {
    unsetenv("CASUAL3D_VIEWER_DIR");
    fs::remove_all(root_);
  }
  fs::path root_;
};

TEST_F(ViewerAssetsTest, FindsTheViewerThroughTheEnvironment) {
  EXPECT_EQ(FindViewerDir(), (root_ / "viewer").lexically_normal());
}

TEST_F(ViewerAssetsTest, CopiesTheViewerAndWritesTheIndexPage) {
  WriteViewerPage(root_ / "package");
  EXPECT_EQ(ReadWholeFile(root_ / "package" / "viewer" / "casual3d-viewer.js"), "export {};\n");
  EXPECT_EQ(ReadWholeFile(root_ / "package" / "viewer" / "casual3d-format.wasm").size(), 8u);
  const std::string html = ReadWholeFile(root_ / "package" / "index.html");
  EXPECT_NE(html.find("<script type=\"module\" src=\"viewer/casual3d-viewer.js\"></script>"),
            std::string::npos);
  EXPECT_NE(html.find("<casual3d-viewer src=\"manifest.json\""), std::string::npos);
  EXPECT_NE(html.find("<title>package - casual3d</title>"), std::string::npos);
  // No temporary files are left behind.
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(root_ / "package")) {
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
    files += e.is_regular_file();
  }
  EXPECT_EQ(files, 3);
  // Writing again replaces the files in place.
  WriteWholeFile(root_ / "viewer" / "casual3d-viewer.js", "export const v = 2;\n");
  WriteViewerPage(root_ / "package");
  EXPECT_EQ(ReadWholeFile(root_ / "package" / "viewer" / "casual3d-viewer.js"), "export const v = 2;\n");
}

TEST_F(ViewerAssetsTest, TitlesThePageAsAsked) {
  WriteViewerPage(root_ / "package", {}, "fern");
  EXPECT_NE(ReadWholeFile(root_ / "package" / "index.html").find("<title>fern - casual3d</title>"),
            std::string::npos);
  EXPECT_EQ(FolderName(root_ / "out" / "fern" / ""), "fern");
  EXPECT_EQ(FolderName(root_ / "out" / "fern" / "."), "fern");
  EXPECT_EQ(FolderName("out/fern"), "fern");
}

TEST_F(ViewerAssetsTest, EscapesTheTitle) {
  const std::string html = ViewerPageHtml("a<b>&\"c\"", "viewer/");
  EXPECT_NE(html.find("<title>a&lt;b&gt;&amp;&quot;c&quot;</title>"), std::string::npos);
}

TEST_F(ViewerAssetsTest, CaptureAdviceFillsTheInfoPanel) {
  // Without advice: no info slot, the panel closed.
  const std::string plain = ViewerPageHtml("t", "viewer/");
  EXPECT_EQ(plain.find("slot=\"info\""), std::string::npos);
  EXPECT_EQ(plain.find("info-open"), std::string::npos);
  // A description alone: the panel is there, closed.
  const std::string quiet = ViewerPageHtml("t", "viewer/", {"The camera moved 0.30 m."});
  EXPECT_NE(quiet.find("<div slot=\"info\">\n<h2>About this capture</h2>\n<p>The camera moved 0.30 m.</p>"),
            std::string::npos)
      << quiet;
  EXPECT_EQ(quiet.find("info-open"), std::string::npos);
  // With warnings: open at load, each warning marked, the text escaped.
  WriteViewerPage(root_ / "package", {"The camera moved 1.84 m.", "Photos a<b>.jpg & c.jpg overlap nothing."});
  const std::string html = ReadWholeFile(root_ / "package" / "index.html");
  EXPECT_NE(html.find("<casual3d-viewer src=\"manifest.json\" controls info-open>"), std::string::npos) << html;
  EXPECT_NE(html.find("<p class=\"warning\">Photos a&lt;b&gt;.jpg &amp; c.jpg overlap nothing.</p>"),
            std::string::npos)
      << html;
}

TEST_F(ViewerAssetsTest, RefusesAMissingPackageFolder) {
  try {
    WriteViewerPage(root_ / "nope");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nope: not a folder"), std::string::npos) << e.what();
  }
}

TEST_F(ViewerAssetsTest, NamesThePlacesSearchedWhenTheViewerIsMissing) {
  setenv("CASUAL3D_VIEWER_DIR", (root_ / "empty").c_str(), 1);
  try {
    FindViewerDir();
    // A built viewer in the build tree may legitimately be found instead.
    SUCCEED();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((root_ / "empty").string()), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("CASUAL3D_VIEWER_DIR"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace casual3d::cli
