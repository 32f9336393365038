#include "format/package_reader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "format/package_test_scene.h"

namespace casual3d {
namespace {

// A one-level package of `pano` in 16-pixel tiles, assembled from images
// made by EncodeTileImage (no WebP: PackageReader takes decoded pixels).
class PackageReaderTest : public ::testing::Test {
 protected:
  static constexpr int kWidth = 64, kHeight = 32, kTile = 16;

  void SetUp() override { pano_ = testing::MakePackageTestPanorama(kWidth, kHeight); }

  static Manifest OneLevelManifest() {
    Manifest m;
    m.width = kWidth;
    m.height = kHeight;
    m.tile_size = kTile;
    m.depth.near_m = 0.5;
    m.depth.far_m = 200.0;
    m.depth.bits = 16;
    LevelEntry L;
    L.width = kWidth;
    L.height = kHeight;
    L.columns = kWidth / kTile;
    L.rows = kHeight / kTile;
    for (int row = 0; row < L.rows; ++row) {
      for (int column = 0; column < L.columns; ++column) {
        TileEntry t;
        for (int k = 0; k < kNumTileImageKinds; ++k) {
          t.files[k] = "l0/" + std::to_string(row) + "-" + std::to_string(column) + "." +
                       TileImageKindName(static_cast<TileImageKind>(k)) + ".webp";
          m.files.push_back({t.files[k], 1, std::string(64, '0')});
        }
        L.tiles.push_back(t);
      }
    }
    std::sort(m.files.begin(), m.files.end(),
              [](const FileEntry& a, const FileEntry& b) { return a.path < b.path; });
    m.levels.push_back(L);
    return m;
  }

  // Reads `pano_` back through a PackageReader; `skip`: a (tile, kind) not added.
  StatusOr<TwoLayerPanorama> Read(int skip_tile = -1,
                                  TileImageKind skip_kind = TileImageKind::kColor) {
    StatusOr<PackageReader> reader = PackageReader::Create(SerializeManifest(OneLevelManifest()));
    EXPECT_TRUE(reader.ok()) << reader.status().ToString();
    if (!reader.ok()) return reader.status();
    EXPECT_TRUE(reader->BeginLevel(0).ok());
    const Manifest& m = reader->manifest();
    for (int tile = 0; tile < static_cast<int>(m.levels[0].tiles.size()); ++tile) {
      int x, y, w, h;
      m.TileRect(0, tile, &x, &y, &w, &h);
      for (int k = 0; k < kNumTileImageKinds; ++k) {
        const TileImageKind kind = static_cast<TileImageKind>(k);
        if (tile == skip_tile && kind == skip_kind) continue;
        const Image8 image = EncodeTileImage(pano_, x, y, w, h, kind, m.quantization());
        const Status s = reader->AddTileImage(tile, kind, image.view());
        EXPECT_TRUE(s.ok()) << s.ToString();
      }
    }
    return reader->FinishLevel();
  }

  // A present front node at (x, y) linked to the front node in direction d.
  bool FindFrontLink(int x, int y, Direction d) const {
    const LayerData& f = pano_.layer(kFront);
    const size_t i = static_cast<size_t>(y) * kWidth + x;
    return f.present[i] && GetLink(f.links[i], d) == Link::kFront;
  }

  TwoLayerPanorama pano_;
};

TEST_F(PackageReaderTest, ReadsTheEncodedPanoramaBack) {
  StatusOr<TwoLayerPanorama> read = Read();
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  for (int l = 0; l < kNumLayers; ++l) EXPECT_EQ(read->layer(l).links, pano_.layer(l).links);
}

// A link refused names the graph image holding it and, when another tile holds
// the node it points at, that tile's graph image too (spec/package.md Sec. 9.1).
TEST_F(PackageReaderTest, LinkErrorsNameTheGraphFiles) {
  // Across the tile boundary at x = 16: front node (15, y) links right, the
  // node at (16, y) of tile 0-1 loses its link back.
  int y = 0;
  while (y < kHeight && !FindFrontLink(15, y, kRight)) ++y;
  ASSERT_LT(y, kHeight) << "no front link across x = 16";
  const size_t j = static_cast<size_t>(y) * kWidth + 16;
  uint8_t& back = pano_.layer(kFront).links[j];
  const uint8_t saved = back;
  back = SetLink(back, kLeft, Link::kNone);
  StatusOr<TwoLayerPanorama> read = Read();
  ASSERT_FALSE(read.ok());
  const std::string row = std::to_string(y / kTile);
  EXPECT_EQ(read.status().code(), StatusCode::kInvalidData);
  EXPECT_EQ(read.status().message(),
            "l0/" + row + "-0.graph.webp: front node (15, " + std::to_string(y) +
                "): right link to front node (16, " + std::to_string(y) +
                ") is not mutual (the node it points at is in l0/" + row + "-1.graph.webp)");
  back = saved;

  // Within one tile (front nodes (14, y) and (15, y) of tile 0): no second file.
  const size_t i = static_cast<size_t>(y) * kWidth + 15;
  uint8_t& left = pano_.layer(kFront).links[i];
  const uint8_t saved_left = left;
  left = SetLink(left, kLeft, Link::kBack);  // No back node at (14, y) links to it.
  read = Read();
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message().rfind("l0/" + row + "-0.graph.webp: front node (1", 0), 0u)
      << read.status().message();
  EXPECT_NE(read.status().message().find(" link "), std::string::npos) << read.status().message();
  EXPECT_EQ(read.status().message().find("points at is in"), std::string::npos)
      << read.status().message();
  left = saved_left;

  // Leaving the panorama through the top row.
  int x = 0;
  while (x < kWidth && !pano_.present(kFront, x, 0)) ++x;
  ASSERT_LT(x, kWidth);
  uint8_t& top = pano_.layer(kFront).links[x];
  top = SetLink(top, kUp, Link::kFront);
  read = Read();
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message(),
            "l0/0-" + std::to_string(x / kTile) + ".graph.webp: front node (" + std::to_string(x) +
                ", 0): up link points outside the panorama (rows do not wrap)");
}

// FinishLevel names the image not added, without naming the level: its
// callers do (the level is theirs to report once).
TEST_F(PackageReaderTest, FinishLevelNamesAMissingImage) {
  StatusOr<TwoLayerPanorama> read = Read(5, TileImageKind::kNormal);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(read.status().message(),
            "l0/1-1.normal.webp: not added; the level needs every image of every tile");
}

// ReadManifest: a problem of manifest.json named as such.
TEST_F(PackageReaderTest, ReadManifestNamesTheManifest) {
  MemoryFileSource source;
  std::string text = SerializeManifest(OneLevelManifest());
  source.Add(kManifestFileName, std::vector<uint8_t>(text.begin(), text.end()));
  StatusOr<Manifest> ok = ReadManifest(source);
  ASSERT_TRUE(ok.ok()) << ok.status().ToString();
  EXPECT_EQ(ok->levels.size(), 1u);
  text.replace(text.find("\"1."), 3, "\"3.");
  MemoryFileSource newer;
  newer.Add(kManifestFileName, std::vector<uint8_t>(text.begin(), text.end()));
  StatusOr<Manifest> refused = ReadManifest(newer);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().message().rfind("manifest.json: version 3.", 0), 0u)
      << refused.status().message();
}

}  // namespace
}  // namespace casual3d
