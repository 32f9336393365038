// Captures as people make them, through the `casual3d` program: a synthetic
// capture's photos as HEIC (libheif's encoder, with the photos' EXIF), as an
// MP4 clip (FFmpeg), and among bad files; each registered or refused with one
// line. Runs COLMAP three times on 640x480 photos (about a minute and a half).

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <libheif/heif.h>
#include <nlohmann/json.hpp>

#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"
#include "tests/casual3d_cli.h"

namespace casual3d {
namespace {

namespace fs = std::filesystem;

using testing::Casual3d;
using testing::CommandRun;

heif_error Append(heif_context*, const void* data, size_t size, void* out) {
  static_cast<std::string*>(out)->append(static_cast<const char*>(data), size);
  return {heif_error_Ok, heif_suberror_Unspecified, "ok"};
}

// The JPEG's pixels as an 8-bit HEIC carrying the JPEG's EXIF block, as phones write them.
std::string JpegToHeic(const std::string& jpeg) {
  const Image8 rgb = io::DecodeImage(jpeg, "photo");
  heif_context* ctx = heif_context_alloc();
  heif_encoder* encoder = nullptr;
  heif_context_get_encoder_for_format(ctx, heif_compression_HEVC, &encoder);
  heif_encoder_set_lossy_quality(encoder, 92);
  heif_image* image = nullptr;
  heif_image_create(rgb.width(), rgb.height(), heif_colorspace_RGB, heif_chroma_interleaved_RGB, &image);
  heif_image_add_plane(image, heif_channel_interleaved, rgb.width(), rgb.height(), 8);
  int stride = 0;
  uint8_t* plane = heif_image_get_plane(image, heif_channel_interleaved, &stride);
  for (int y = 0; y < rgb.height(); ++y) std::copy_n(&rgb.at(0, y, 0), rgb.width() * 3, plane + y * stride);
  heif_image_handle* handle = nullptr;
  heif_context_encode_image(ctx, image, encoder, nullptr, &handle);
  if (jpeg.size() > 10 && static_cast<uint8_t>(jpeg[3]) == 0xE1) {  // APP1 "Exif\0\0" + TIFF.
    const size_t length = (static_cast<uint8_t>(jpeg[4]) << 8) | static_cast<uint8_t>(jpeg[5]);
    heif_context_add_exif_metadata(ctx, handle, jpeg.data() + 6, static_cast<int>(length - 2));
  }
  std::string out;
  heif_writer writer{1, &Append};
  heif_context_write(ctx, &writer, &out);
  heif_image_handle_release(handle);
  heif_image_release(image);
  heif_encoder_release(encoder);
  heif_context_free(ctx);
  return out;
}

class CaptureInputTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("capture_input_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    const CommandRun synth = Casual3d("synth -o " + (root_ / "cap").string() + " --width 640 --panorama-width 256");
    ASSERT_EQ(synth.exit_code, 0) << synth.output;
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }
  static nlohmann::json Json(const fs::path& path) {
    return nlohmann::json::parse(io::ReadFile(path.string()));
  }
  static fs::path root_;
};
fs::path CaptureInputTest::root_;

TEST_F(CaptureInputTest, HeicPhotosRegisterWithTheirExifFocalLength) {
  fs::create_directories(root_ / "heic");
  for (const auto& e : fs::directory_iterator(root_ / "cap" / "images")) {
    io::WriteFileAtomic((root_ / "heic" / e.path().stem()).string() + ".HEIC",
                        JpegToHeic(io::ReadFile(e.path().string())));
  }
  // One thread in every reconstruction here: COLMAP's multi-threaded mapper
  // once registered 12 of these 16 small photos under a full parallel test
  // run (as in capture_advice_test).
  const CommandRun run = Casual3d("sparse " + (root_ / "heic").string() + " -o " +
                           (root_ / "sp_heic").string() + " --threads 1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("16 of 16 photos registered"), std::string::npos) << run.output;
  // The focal prior came from the HEIF's Exif block (the synthetic camera's 502.3 px).
  const std::string log = io::ReadFile((root_ / "sp_heic" / "sparse_log.txt").string());
  EXPECT_NE(log.find("focal prior 502.2"), std::string::npos);
}

TEST_F(CaptureInputTest, Mp4ClipRegistersFromPickedFrames) {
  // Each photo held for 3 frames at 6 fps: 48 frames, 16 distinct views.
  const std::string clip = (root_ / "clip.mp4").string();
  ASSERT_EQ(std::system(("ffmpeg -v error -y -framerate 2 -i " + (root_ / "cap" / "images").string() +
                         "/%04d.jpg -c:v libx264 -crf 15 -pix_fmt yuv420p -r 6 " + clip).c_str()),
            0);
  // Video carries no focal length; the synthetic camera's is given.
  const CommandRun run = Casual3d("sparse " + clip + " -o " + (root_ / "sp_video").string() +
                           " --threads 1 --focal-px 502.3");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json stage = Json(root_ / "sp_video" / "stage.json");
  EXPECT_EQ(stage["input_type"], "video");
  EXPECT_EQ(stage["video"]["frames"], 48);
  EXPECT_EQ(stage["video"]["picked"].size(), 16u);  // One frame per view, not 48.
  EXPECT_GE(stage["num_registered"].get<int>(), 15);
  const std::string log = io::ReadFile((root_ / "sp_video" / "sparse_log.txt").string());
  EXPECT_NE(log.find("frame selection: 48 frames"), std::string::npos);
}

TEST_F(CaptureInputTest, BadFilesAmongGoodOnesAreListedInTheReport) {
  const fs::path in = root_ / "bad";
  fs::create_directories(in);
  for (const auto& e : fs::directory_iterator(root_ / "cap" / "images")) fs::copy(e.path(), in / e.path().filename());
  const std::string photo = io::ReadFile((in / "0003.jpg").string());
  io::WriteFileAtomic((in / "0003_copy.jpg").string(), photo);
  io::WriteFileAtomic((in / "cut.jpg").string(), photo.substr(0, photo.size() / 3));
  const CommandRun run = Casual3d("reconstruct " + in.string() + " -o " + (root_ / "out_bad").string() +
                           " --to sparse --threads 1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("cut.jpg: truncated JPEG"), std::string::npos) << run.output;
  const nlohmann::json report = Json(root_ / "out_bad" / "report.json");
  ASSERT_EQ(report["skipped"].size(), 2u) << report.dump();
  EXPECT_EQ(report["skipped"][0]["file"], "0003_copy.jpg");
  EXPECT_EQ(report["skipped"][0]["reason"], "same bytes as 0003.jpg");
  EXPECT_EQ(report["skipped"][1]["file"], "cut.jpg");
  EXPECT_EQ(report["results"]["sparse"]["registered"], 16);

  // Too few usable photos: one line, non-zero exit, no output folder.
  const fs::path few = root_ / "few";
  fs::create_directories(few);
  fs::copy(in / "0000.jpg", few / "a.jpg");
  fs::copy(in / "0000.jpg", few / "b.jpg");
  fs::copy(in / "cut.jpg", few / "c.jpg");
  const CommandRun refused = Casual3d("sparse " + few.string() + " -o " + (root_ / "sp_few").string());
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("1 usable photos of 3; at least 3 are needed"), std::string::npos)
      << refused.output;
  EXPECT_FALSE(fs::exists(root_ / "sp_few"));
}

}  // namespace
}  // namespace casual3d
