#include "format/manifest.h"

#include <string>

#include <gtest/gtest.h>

namespace casual3d {
namespace {

Manifest SmallManifest() {
  Manifest m;
  m.generator = "test";
  m.width = 64;
  m.height = 32;
  m.tile_size = 32;
  m.frame.centre[0] = 0.1;
  m.depth.near_m = 0.75;
  m.depth.far_m = 40.0;
  m.depth.bits = 12;
  m.normal.bits = 7;
  const char* kinds[] = {"color", "depth", "normal", "graph"};
  const int sizes[][4] = {{64, 32, 2, 1}, {32, 16, 1, 1}};
  for (int l = 0; l < 2; ++l) {
    LevelEntry L{sizes[l][0], sizes[l][1], sizes[l][2], sizes[l][3], {}};
    for (int t = 0; t < L.columns * L.rows; ++t) {
      TileEntry tile;
      for (int k = 0; k < 4; ++k) {
        tile.files[k] = "l" + std::to_string(l) + "/0-" + std::to_string(t) + "." + kinds[k] + ".webp";
        m.files.push_back({tile.files[k], uint64_t(100 + k), std::string(64, 'a' + k)});
      }
      L.tiles.push_back(tile);
    }
    m.levels.push_back(L);
  }
  std::sort(m.files.begin(), m.files.end(),
            [](const FileEntry& a, const FileEntry& b) { return a.path < b.path; });
  return m;
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

TEST(ManifestTest, SerializeParseRoundTrip) {
  const Manifest m = SmallManifest();
  ASSERT_TRUE(m.Validate().ok()) << m.Validate().ToString();
  const std::string text = SerializeManifest(m);
  StatusOr<Manifest> back = ParseManifest(text);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(SerializeManifest(*back), text);
  EXPECT_EQ(back->depth.bits, 12);
  EXPECT_EQ(back->normal.bits, 7);
  EXPECT_EQ(back->frame.centre[0], 0.1);
  EXPECT_EQ(back->LevelBytes(0), 2u * (100 + 101 + 102 + 103));
  int x, y, w, h;
  back->TileRect(0, 1, &x, &y, &w, &h);
  EXPECT_EQ(x, 32);
  EXPECT_EQ(w, 32);
  ASSERT_NE(back->FindFile("l1/0-0.graph.webp"), nullptr);
  EXPECT_EQ(back->FindFile("l1/0-0.graph.webp")->bytes, 103u);
  EXPECT_EQ(back->FindFile("l9/0-0.graph.webp"), nullptr);
}

TEST(ManifestTest, VersioningRules) {
  const std::string text = SerializeManifest(SmallManifest());
  // Unknown optional members and a newer minor version are accepted.
  StatusOr<Manifest> newer = ParseManifest(
      Replace(Replace(text, "\"version\": \"1.0\"", "\"version\": \"1.7\""), "\"tile_size\"",
              "\"future\": {\"x\": [1, 2]}, \"tile_size\""));
  ASSERT_TRUE(newer.ok()) << newer.status().ToString();
  EXPECT_EQ(newer->version_minor, 7);
  EXPECT_TRUE(ParseManifest(Replace(text, "\"1.0\"", "\"2.0\"")).ok());
  EXPECT_TRUE(ParseManifest(Replace(text, "\"1.0\"", "\"2.9\"")).ok());
  const StatusOr<Manifest> major3 = ParseManifest(Replace(text, "\"1.0\"", "\"3.0\""));
  EXPECT_EQ(major3.status().code(), StatusCode::kUnsupportedVersion);
  EXPECT_EQ(major3.status().message(),
            "manifest.json: version 3.0 is not supported (this reader reads 1.x and 2.x)");
  EXPECT_EQ(ParseManifest(Replace(text, "\"1.0\"", "\"0.9\"")).status().code(),
            StatusCode::kUnsupportedVersion);
  EXPECT_EQ(ParseManifest(Replace(text, "\"1.0\"", "\"1\"")).status().code(),
            StatusCode::kInvalidData);
}

// Level 1 a quarter of level 0's width: version 2.x only (spec/package.md
// Sec. 2); its shift must be above the level before's and exact.
TEST(ManifestTest, LevelsMayLeaveOutHalvingsFromVersion2) {
  Manifest m = SmallManifest();
  m.levels[1].width = 16;
  m.levels[1].height = 8;
  const Status v1 = m.Validate();
  EXPECT_EQ(v1.code(), StatusCode::kInvalidData);
  EXPECT_EQ(v1.message(), "levels[1]: size 16x8 is not the full size 64x32 divided by 2^1");
  m.version_major = 2;
  EXPECT_TRUE(m.Validate().ok()) << m.Validate().ToString();
  const StatusOr<Manifest> parsed = ParseManifest(SerializeManifest(m));
  ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
  EXPECT_EQ(parsed->levels[1].width, 16);
  // Halved alike in both directions, or not at all.
  m.levels[1].height = 16;
  EXPECT_EQ(m.Validate().message(),
            "levels[1]: size 16x16 is not the full size 64x32 divided by 2^s for an s above the "
            "level before's 0");
  // Not finer than the level before, nor equal to it.
  m.levels[1] = m.levels[0];
  EXPECT_EQ(m.Validate().message(),
            "levels[1]: size 64x32 is not the full size 64x32 divided by 2^s for an s above the "
            "level before's 0");
  m = SmallManifest();
  m.version_major = 2;
  m.levels.push_back(m.levels[1]);
  EXPECT_EQ(m.Validate().message(),
            "levels[2]: size 32x16 is not the full size 64x32 divided by 2^s for an s above the "
            "level before's 1");
  // Level 0 is the full size in every version.
  m = SmallManifest();
  m.version_major = 2;
  m.levels.erase(m.levels.begin());
  EXPECT_EQ(m.Validate().message(),
            "levels[0]: size 32x16 is not the full size 64x32 divided by 2^0");
}

TEST(ManifestTest, LossyNormalEncoding) {
  Manifest m = SmallManifest();
  m.version_minor = 2;
  m.normal.type = NormalEncoding::kOctahedralLossy;
  m.normal.bits = 8;
  m.normal.mean_error_deg = 2.5;
  m.normal.p99_error_deg = 8;
  ASSERT_TRUE(m.Validate().ok()) << m.Validate().ToString();
  const std::string text = SerializeManifest(m);
  EXPECT_NE(text.find("\"type\": \"octahedral-lossy\""), std::string::npos) << text;
  EXPECT_EQ(text.find("\"bits\": 8"), std::string::npos) << "the lossy encoding has no bits";
  StatusOr<Manifest> back = ParseManifest(text);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_TRUE(back->normal.lossy());
  EXPECT_EQ(back->normal.bits, 8);
  EXPECT_EQ(back->normal.mean_error_deg, 2.5);
  EXPECT_EQ(back->normal.p99_error_deg, 8);
  EXPECT_EQ(SerializeManifest(*back), text);
  // Bounds are required and in (0, 90].
  for (const auto& [from, to] :
       {std::make_pair("\"p99_error_deg\": 8", "\"p99_error_deg\": 0"),
        std::make_pair("\"p99_error_deg\": 8", "\"p99_error_deg\": 91"),
        std::make_pair("\"mean_error_deg\": 2.5", "\"mean_error_deg\": \"2.5\""),
        std::make_pair("\"mean_error_deg\": 2.5,", "")}) {
    StatusOr<Manifest> bad = ParseManifest(Replace(text, from, to));
    ASSERT_FALSE(bad.ok()) << to;
    EXPECT_NE(bad.status().message().find("normal_encoding"), std::string::npos)
        << bad.status().ToString();
  }
  // An encoding type this reader does not know is refused, naming it.
  StatusOr<Manifest> unknown =
      ParseManifest(Replace(SerializeManifest(SmallManifest()), "\"octahedral\"", "\"spherical\""));
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.status().code(), StatusCode::kInvalidData);
  EXPECT_NE(unknown.status().message().find("normal_encoding.type: \"spherical\" is not supported"),
            std::string::npos)
      << unknown.status().ToString();
}

TEST(ManifestTest, ErrorsNameTheField) {
  const std::string text = SerializeManifest(SmallManifest());
  struct Case {
    std::string text;
    const char* message;
  } cases[] = {
      {Replace(text, "\"casual3d\"", "\"other\""), "format: \"other\" is not supported"},
      {Replace(text, "\"width\": 64", "\"width\": 65"), "levels[0]: size"},
      {Replace(text, "\"width\": 64", "\"width\": 99999"), "width: 99999 is outside"},
      {Replace(text, "\"height\": 32", "\"height\": \"32\""), "height: expected a number"},
      {Replace(text, "\"tile_size\": 32", "\"tile_size\": 2"), "tile_size: 2 is outside"},
      {Replace(text, "\"l0/0-1.depth.webp\"", "\"l0/../../etc/passwd\""),
       "levels[0].tiles[1].depth: \"l0/../../etc/passwd\" is not a safe relative path"},
      {Replace(text, "\"path\": \"l0/0-0.color.webp\"", "\"path\": \"/abs\""), "files[0].path"},
      {Replace(text, "\"bits\": 12", "\"bits\": 17"), "depth_encoding.bits: 17 is outside"},
      {Replace(text, "\"near_m\": 0.75", "\"near_m\": -1"), "depth_encoding: depth near_m"},
      {Replace(text, std::string(64, 'a'), std::string(63, 'a') + "G"), "sha256"},
      {Replace(text, "\"columns\": 2", "\"columns\": 3"), "levels[0]: tile grid"},
      {Replace(text, "\"layers\": [\n    \"front\",", "\"layers\": [\n    \"back\","), "layers"},
      {text.substr(0, text.size() / 2), "manifest.json: byte"},
  };
  for (const Case& c : cases) {
    StatusOr<Manifest> m = ParseManifest(c.text);
    ASSERT_FALSE(m.ok()) << c.message;
    EXPECT_NE(m.status().message().find(c.message), std::string::npos)
        << "expected \"" << c.message << "\" in: " << m.status().message();
  }
}

// spec/package.md Sec. 3: integers are numbers with an integral value;
// nesting counts arrays and objects enclosing each other with the root object
// at 1, and 16 is allowed; near_m = far_m is refused; files entries that no
// tile uses are allowed.
TEST(ManifestTest, ClarifiedRules) {
  const std::string text = SerializeManifest(SmallManifest());
  for (const char* integral : {"32.0", "3.2e1", "320e-1"}) {
    StatusOr<Manifest> m =
        ParseManifest(Replace(text, "\"tile_size\": 32", std::string("\"tile_size\": ") + integral));
    ASSERT_TRUE(m.ok()) << integral << ": " << m.status().ToString();
    EXPECT_EQ(m->tile_size, 32);
  }
  EXPECT_NE(ParseManifest(Replace(text, "\"tile_size\": 32", "\"tile_size\": 32.5"))
                .status()
                .message()
                .find("tile_size: expected an integer"),
            std::string::npos);
  // An extension member nested n deep in all: the root object, then n - 1
  // arrays.
  auto nested = [&](int n) {
    const std::string value = std::string(n - 1, '[') + std::string(n - 1, ']');
    return Replace(text, "\"tile_size\"", "\"x_nest\": " + value + ", \"tile_size\"");
  };
  EXPECT_TRUE(ParseManifest(nested(kMaxManifestNesting)).ok());
  const Status deep = ParseManifest(nested(kMaxManifestNesting + 1)).status();
  EXPECT_EQ(deep.code(), StatusCode::kLimitExceeded);
  EXPECT_NE(deep.message().find("nesting deeper than 16"), std::string::npos) << deep.message();
  EXPECT_TRUE(ParseManifest(nested(kMaxManifestNesting + 1),
                            ReaderChecks::AllBut(ReaderCheck::kNestingTooDeep))
                  .ok());

  const std::string flat = Replace(text, "\"far_m\": 40", "\"far_m\": 0.75");
  const Status equal = ParseManifest(flat).status();
  EXPECT_EQ(equal.code(), StatusCode::kInvalidData);
  EXPECT_NE(equal.message().find("depth_encoding: near_m = far_m = 0.75"), std::string::npos)
      << equal.message();
  EXPECT_TRUE(ParseManifest(flat, ReaderChecks::AllBut(ReaderCheck::kNearEqualsFar)).ok());

  Manifest extra = SmallManifest();
  extra.files.push_back({"zz/unused.bin", 5, std::string(64, 'e')});
  StatusOr<Manifest> with_extra = ParseManifest(SerializeManifest(extra));
  ASSERT_TRUE(with_extra.ok()) << with_extra.status().ToString();
  EXPECT_EQ(with_extra->files.size(), 13u);
}

TEST(ManifestTest, SafePaths) {
  for (const char* good : {"a", "l0/0-0.color.webp", "x/y/z.webp", "..a", "a..b"})
    EXPECT_TRUE(IsSafePackagePath(good)) << good;
  for (const char* bad : {"", "/a", "a/", "a//b", "../a", "a/../b", "./a", "a\\b", "a b", "c:x",
                          "%2e%2e/a", "a\n"})
    EXPECT_FALSE(IsSafePackagePath(bad)) << bad;
  EXPECT_FALSE(IsSafePackagePath(std::string(256, 'a')));
  EXPECT_TRUE(IsSafePackagePath(std::string(255, 'a')));
}

TEST(ManifestTest, ViewHintsRoundTripAndChecks) {
  Manifest m = SmallManifest();
  ViewHints h;
  h.yaw_deg = -12.5;
  h.pitch_deg = 3.0;
  h.fov_deg = 62.0;
  h.content_yaw_min_deg = 150.0;  // Across the seam.
  h.content_yaw_max_deg = 215.0;
  h.content_pitch_min_deg = -40.0;
  h.content_pitch_max_deg = 45.0;
  h.volume_radius = 0.12;
  h.metric = true;
  m.view = h;
  m.version_minor = 1;
  const std::string text = SerializeManifest(m);
  EXPECT_NE(text.find("\"version\": \"1.1\""), std::string::npos);
  StatusOr<Manifest> back = ParseManifest(text);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_TRUE(back->view.has_value());
  EXPECT_TRUE(*back->view == h);
  EXPECT_EQ(SerializeManifest(*back), text);

  // Each member is checked and named.
  auto refused = [&](const std::string& from, const std::string& to, const std::string& names) {
    StatusOr<Manifest> r = ParseManifest(Replace(text, from, to));
    ASSERT_FALSE(r.ok()) << to;
    EXPECT_NE(r.status().message().find(names), std::string::npos) << r.status().message();
  };
  refused("\"fov_deg\": 62", "\"fov_deg\": 170", "view.fov_deg");
  refused("\"volume_radius\": 0.12", "\"volume_radius\": 0", "view.volume_radius");
  refused("\"volume_radius\": 0.12", "\"volume_radius\": \"big\"", "view.volume_radius");
  refused("\"metric\": true", "\"metric\": 1", "view.metric");
  refused("\"yaw_deg\": -12.5", "\"yaw_deg\": 200", "view.yaw_deg");
  refused("\"content_pitch_deg\": [\n      -40,\n      45\n    ]", "\"content_pitch_deg\": [45, -40]",
          "view.content_pitch_deg");
  // Without "view", a 1.0 manifest parses with no hints.
  EXPECT_FALSE(ParseManifest(SerializeManifest(SmallManifest()))->view.has_value());
}

}  // namespace
}  // namespace casual3d
