#include "base/exr_file.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include "base/testing/scratch_dir.h"

namespace casual3d::base {
namespace {

namespace fs = std::filesystem;

class ExrFileTest : public casual3d::testing::TestWithScratchDir {
 protected:
  size_t FilesInFolder() const {
    return std::distance(fs::directory_iterator(dir_), fs::directory_iterator());
  }
};

template <typename T>
ExrSlice Plane(const std::string& name, ExrPixelType type, std::vector<T>& plane, int width,
               int first_row = 0) {
  return {name, type,
          reinterpret_cast<char*>(plane.data() + static_cast<size_t>(first_row) * width), sizeof(T),
          sizeof(T) * width};
}

// Three channel types, attributes, and rows written and read in blocks.
TEST_F(ExrFileTest, RoundTripInBlocksOfRows) {
  const int w = 5, h = 7;
  std::vector<float> z(w * h), half_values(w * h);
  std::vector<uint32_t> ids(w * h);
  for (int i = 0; i < w * h; ++i) {
    z[i] = 0.1f * i + 1e-7f;
    half_values[i] = 0.5f * i;  // Exact in half.
    ids[i] = 1000u * i;
  }
  ExrHeader header;
  header.width = w;
  header.height = h;
  header.channels = {
      {"Z", ExrPixelType::kFloat}, {"H", ExrPixelType::kHalf}, {"id", ExrPixelType::kUint}};
  header.string_attributes = {{"casual3d.format", "test"}};
  header.v3d_attributes = {{"casual3d.centre", {1.5, -2, 3}}};
  header.m33d_attributes = {{"casual3d.rotation", {1, 2, 3, 4, 5, 6, 7, 8, 9}}};
  const std::string path = scratch_.Path("a.exr");
  {
    StatusOr<ExrWriter> writer = ExrWriter::Create(path, header, 2);
    ASSERT_TRUE(writer.ok()) << writer.status().ToString();
    for (int y0 = 0; y0 < h; y0 += 3) {
      const int rows = std::min(3, h - y0);
      ASSERT_TRUE(writer
                      ->WriteRows(rows, {Plane("Z", ExrPixelType::kFloat, z, w, y0),
                                         Plane("H", ExrPixelType::kFloat, half_values, w, y0),
                                         Plane("id", ExrPixelType::kUint, ids, w, y0)})
                      .ok());
    }
    EXPECT_FALSE(fs::exists(path));  // Not before Commit().
    ASSERT_TRUE(writer->Commit().ok());
  }
  EXPECT_EQ(FilesInFolder(), 1u);

  StatusOr<ExrReader> reader = ExrReader::Open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().ToString();
  EXPECT_EQ(reader->width(), w);
  EXPECT_EQ(reader->height(), h);
  ASSERT_EQ(reader->channels().size(), 3u);
  EXPECT_EQ(reader->channels()[0].name, "H");  // Sorted by name.
  EXPECT_EQ(reader->FindChannel("H")->type, ExrPixelType::kHalf);
  EXPECT_EQ(reader->FindChannel("id")->type, ExrPixelType::kUint);
  EXPECT_EQ(reader->FindChannel("nope"), nullptr);
  EXPECT_EQ(*reader->StringAttribute("casual3d.format"), "test");
  EXPECT_FALSE(reader->StringAttribute("casual3d.centre"));  // Another type.
  EXPECT_EQ(*reader->V3dAttribute("casual3d.centre"), (std::array<double, 3>{1.5, -2, 3}));
  EXPECT_EQ((*reader->M33dAttribute("casual3d.rotation"))[5], 6.0);

  std::vector<float> z2(w * h, -1), h2(w * h, -1), ids_as_float(w * h);
  std::vector<uint32_t> ids2(w * h);
  for (int y0 = 0; y0 < h; y0 += 4) {
    const int rows = std::min(4, h - y0);
    ASSERT_TRUE(reader
                    ->ReadRows(y0, rows,
                               {Plane("Z", ExrPixelType::kFloat, z2, w, y0),
                                Plane("H", ExrPixelType::kFloat, h2, w, y0),
                                Plane("id", ExrPixelType::kUint, ids2, w, y0)})
                    .ok());
  }
  EXPECT_EQ(z2, z);
  EXPECT_EQ(h2, half_values);
  EXPECT_EQ(ids2, ids);
  // Types convert on reading.
  ASSERT_TRUE(reader->ReadRows(0, h, {Plane("id", ExrPixelType::kFloat, ids_as_float, w)}).ok());
  EXPECT_EQ(ids_as_float[7], 7000.0f);
}

TEST_F(ExrFileTest, ErrorsNameTheFile) {
  EXPECT_EQ(ExrReader::Open(scratch_.Path("none.exr")).status().code(), StatusCode::kNotFound);
  std::ofstream(scratch_.Path("text.exr")) << "not an image";
  const Status text = ExrReader::Open(scratch_.Path("text.exr")).status();
  EXPECT_EQ(text.code(), StatusCode::kInvalidData);
  EXPECT_EQ(text.message(), scratch_.Path("text.exr") + ": not an OpenEXR file");

  ExrHeader header;
  header.width = 2;
  header.height = 1;
  header.channels = {{"Y"}};
  std::vector<float> y = {1, 2};
  StatusOr<ExrWriter> w = ExrWriter::Create(scratch_.Path("y.exr"), header);
  ASSERT_TRUE(w.ok());
  ASSERT_TRUE(w->WriteRows(1, {Plane("Y", ExrPixelType::kFloat, y, 2)}).ok());
  ASSERT_TRUE(w->Commit().ok());
  StatusOr<ExrReader> r = ExrReader::Open(scratch_.Path("y.exr"));
  ASSERT_TRUE(r.ok());
  const Status missing = r->ReadRows(0, 1, {Plane("Z", ExrPixelType::kFloat, y, 2)});
  EXPECT_EQ(missing.code(), StatusCode::kInvalidData);
  EXPECT_EQ(missing.message(), scratch_.Path("y.exr") + ": OpenEXR channel 'Z' is missing");

  header.channels = {{"Y"}, {"Y"}};
  EXPECT_EQ(ExrWriter::Create(scratch_.Path("b.exr"), header).status().code(),
            StatusCode::kInvalidArgument);
  header.channels = {{"Y"}};
  const Status no_folder = ExrWriter::Create(scratch_.Path("no/folder/c.exr"), header).status();
  EXPECT_EQ(no_folder.code(), StatusCode::kIoError);
  EXPECT_EQ(
      no_folder.message().rfind(scratch_.Path("no/folder/c.exr") + ": cannot write OpenEXR (", 0),
      0u)
      << no_folder.message();
}

// A writer given up before Commit() leaves neither the file nor a temporary one.
TEST_F(ExrFileTest, AnAbandonedWriterLeavesNothing) {
  ExrHeader header;
  header.width = 4;
  header.height = 4;
  header.channels = {{"Z"}};
  std::vector<float> z(16, 1.0f);
  {
    StatusOr<ExrWriter> w = ExrWriter::Create(scratch_.Path("a.exr"), header);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE(w->WriteRows(2, {Plane("Z", ExrPixelType::kFloat, z, 4)}).ok());
    EXPECT_EQ(w->Commit().code(), StatusCode::kInternal);  // Two rows are missing.
    EXPECT_EQ(w->WriteRows(3, {Plane("Z", ExrPixelType::kFloat, z, 4)}).code(),
              StatusCode::kInternal);  // Past the last row.
  }
  EXPECT_EQ(FilesInFolder(), 0u);
}

}  // namespace
}  // namespace casual3d::base
