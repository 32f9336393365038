// Conformance vectors of spec/package.md Sec. 9 (spec/vectors/): checks that
// every valid vector decodes to the values in expected.json and that every
// invalid vector is refused. With CASUAL3D_UPDATE_VECTORS=1 in the environment
// it first (re)writes the vectors from procedural panoramas.

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "encoder/package_writer.h"
#include "encoder/webp_codec.h"
#include "format/file_source.h"
#include "format/json.h"
#include "format/package_reader.h"
#include "format/package_test_scene.h"
#include "format/sha256.h"
#include "format/tile_codec.h"

namespace casual3d::encoder {
namespace {

namespace fs = std::filesystem;
using json::Value;

fs::path VectorsDir() {
  const char* source = std::getenv("CASUAL3D_SOURCE_DIR");
  return fs::path(source != nullptr ? source : ".") / "spec" / "vectors";
}

// The decoded values that spec/package.md Sec. 9 lists for one level.
Value Summary(const TwoLayerPanorama& pano) {
  Value level = Value::Object();
  level.Set("width", Value::Number(pano.width()));
  level.Set("height", Value::Number(pano.height()));
  Value present = Value::Array(), rgb = Value::Array(), depth = Value::Array(),
        normal = Value::Array();
  std::vector<uint8_t> graph;
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& L = pano.layer(l);
    double count = 0, rgb_sum = 0, depth_sum = 0, n[3] = {0, 0, 0};
    for (size_t i = 0; i < L.present.size(); ++i) {
      if (!L.present[i]) continue;
      ++count;
      depth_sum += L.depth_m[i];
      for (int c = 0; c < 3; ++c) {
        rgb_sum += L.rgb[3 * i + c];
        n[c] += L.normal[3 * i + c];
      }
    }
    present.Append(Value::Number(count));
    rgb.Append(Value::Number(rgb_sum));
    depth.Append(Value::Number(depth_sum));
    Value nv = Value::Array();
    for (double c : n) nv.Append(Value::Number(c));
    normal.Append(std::move(nv));
    graph.insert(graph.end(), L.present.begin(), L.present.end());
    graph.insert(graph.end(), L.label.begin(), L.label.end());
    graph.insert(graph.end(), L.links.begin(), L.links.end());
  }
  level.Set("present", std::move(present));
  level.Set("rgb_sum", std::move(rgb));
  level.Set("depth_sum_m", std::move(depth));
  level.Set("normal_sum", std::move(normal));
  level.Set("graph_sha256", Value::String(Sha256Hex(graph.data(), graph.size())));
  return level;
}

std::vector<uint8_t> ReadBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void WriteBytes(const fs::path& p, const std::string& s) {
  std::ofstream(p, std::ios::binary) << s;
}

// Replaces a file of a package and fixes its manifest entry, so that only the
// file's content is wrong.
PackageFiles ReplaceFile(PackageFiles files, const std::string& path, std::vector<uint8_t> bytes) {
  std::string manifest(files[0].second.begin(), files[0].second.end());
  for (auto& [p, b] : files) {
    if (p != path) continue;
    const std::string old_hash = Sha256Hex(b.data(), b.size());
    const std::string old_size = "\"bytes\": " + std::to_string(b.size());
    b = std::move(bytes);
    const size_t at = manifest.find("\"path\": \"" + path + "\"");
    manifest.replace(manifest.find(old_size, at), old_size.size(),
                     "\"bytes\": " + std::to_string(b.size()));
    manifest.replace(manifest.find(old_hash, at), 64, Sha256Hex(b.data(), b.size()));
  }
  files[0].second.assign(manifest.begin(), manifest.end());
  return files;
}

PackageFiles WithManifest(PackageFiles files, const std::string& from, const std::string& to) {
  std::string manifest(files[0].second.begin(), files[0].second.end());
  manifest.replace(manifest.find(from), from.size(), to);
  files[0].second.assign(manifest.begin(), manifest.end());
  return files;
}

void Regenerate() {
  const fs::path dir = VectorsDir();
  fs::create_directories(dir / "invalid");
  WebpImageDecoder decoder;
  Value expected = Value::Object();
  struct Vector {
    const char* name;
    TwoLayerPanorama pano;
    PackageOptions options;
  };
  PackageOptions two_levels;
  two_levels.tile_size = 16;
  two_levels.levels = 2;
  two_levels.num_threads = 1;
  two_levels.generator = "casual3d spec/vectors";
  PackageOptions one_level = two_levels;
  one_level.levels = 1;
  one_level.tile_size = 32;
  one_level.depth_bits = 16;
  one_level.normal_bits = 6;
  TwoLayerPanorama front_only = casual3d::testing::MakePackageTestPanorama(48, 24, 7);
  for (int l : {kBack}) {
    LayerData& L = front_only.layer(l);
    std::fill(L.present.begin(), L.present.end(), 0);
    std::fill(L.rgb.begin(), L.rgb.end(), 0);
    std::fill(L.depth_m.begin(), L.depth_m.end(), 0.0f);
    std::fill(L.normal.begin(), L.normal.end(), 0.0f);
    std::fill(L.label.begin(), L.label.end(), 0);
    std::fill(L.links.begin(), L.links.end(), 0);
  }
  // Front nodes that linked to removed back nodes lose those links.
  for (size_t i = 0; i < front_only.layer(kFront).links.size(); ++i) {
    uint8_t& links = front_only.layer(kFront).links[i];
    for (int d = 0; d < kNumDirections; ++d)
      if (GetLink(links, static_cast<Direction>(d)) == Link::kBack)
        links = SetLink(links, static_cast<Direction>(d), Link::kNone);
  }
  Vector vectors[] = {
      {"two-layer-64x32", casual3d::testing::MakePackageTestPanorama(64, 32, 3), two_levels},
      {"front-only-48x24", std::move(front_only), one_level},
  };
  PackageFiles first_files;
  for (Vector& v : vectors) {
    ASSERT_TRUE(v.pano.Validate().ok()) << v.name << ": " << v.pano.Validate().ToString();
    StatusOr<PackageFiles> files = EncodePackage(v.pano, v.options);
    ASSERT_TRUE(files.ok()) << files.status().ToString();
    ASSERT_TRUE(WritePackageFolder(*files, (dir / v.name).string()).ok());
    ASSERT_TRUE(WritePackageSingleFile(*files, (dir / (std::string(v.name) + ".c3d")).string()).ok());
    MemoryFileSource source;
    for (const auto& [p, b] : *files) source.Add(p, b);
    Value levels = Value::Array();
    for (int level = 0; level < (v.options.levels); ++level) {
      ReadOptions read;
      read.level = level;
      StatusOr<TwoLayerPanorama> pano = ReadPackage(source, decoder, read);
      ASSERT_TRUE(pano.ok()) << pano.status().ToString();
      levels.Append(Summary(*pano));
    }
    expected.Set(v.name, std::move(levels));
    if (first_files.empty()) first_files = *files;
  }
  WriteBytes(dir / "expected.json", json::Serialize(expected, 2) + "\n");

  // Invalid packages: each breaks one rule of spec/package.md.
  const std::string tile = "l0/0-1.graph.webp";
  std::vector<uint8_t> flipped;
  for (const auto& [p, b] : first_files)
    if (p == tile) flipped = b;
  flipped[flipped.size() / 2] ^= 0x10;
  Image8 graph(16, 16, 3, 0);
  graph.at(5, 5, 2) = 0x80;  // Reserved flag bit.
  WebpEncodeOptions lossless;
  lossless.lossless = true;
  const Image8& graph_const = graph;
  const std::vector<uint8_t> reserved = *EncodeWebp(graph_const.view(), lossless);
  std::vector<std::pair<std::string, PackageFiles>> invalid = {
      {"checksum-mismatch", [&] {
         PackageFiles f = first_files;
         for (auto& [p, b] : f)
           if (p == tile) b = flipped;
         return f;
       }()},
      {"path-escape", WithManifest(first_files, "\"graph\": \"l0/0-1.graph.webp\"",
                                   "\"graph\": \"l0/../../0-1.graph.webp\"")},
      {"unknown-major", WithManifest(first_files, "\"version\": \"1.0\"", "\"version\": \"2.0\"")},
      {"reserved-flag-bits", ReplaceFile(first_files, tile, reserved)},
      {"wrong-tile-size", ReplaceFile(first_files, "l0/0-1.color.webp", reserved)},
      {"depth-code-above-max", [&] {
         Image8 depth(16, 32, 3, 0);
         depth.at(0, 0, 0) = 0xFF;  // Code 65280 > 4095.
         const Image8& c = depth;
         return ReplaceFile(first_files, "l0/0-1.depth.webp", *EncodeWebp(c.view(), lossless));
       }()},
  };
  for (auto& [name, files] : invalid) {
    fs::remove_all(dir / "invalid" / name);
    fs::create_directories(dir / "invalid" / name);
    for (const auto& [p, b] : files) {
      fs::create_directories((dir / "invalid" / name / p).parent_path());
      WriteBytes(dir / "invalid" / name / p, std::string(b.begin(), b.end()));
    }
  }
}

TEST(PackageVectorsTest, ValidVectorsDecodeToTheExpectedValues) {
  if (std::getenv("CASUAL3D_UPDATE_VECTORS") != nullptr) Regenerate();
  const fs::path dir = VectorsDir();
  if (!fs::exists(dir / "expected.json")) GTEST_SKIP() << "no " << dir << "/expected.json";
  const std::vector<uint8_t> text = ReadBytes(dir / "expected.json");
  StatusOr<Value> expected = json::Parse(std::string_view(reinterpret_cast<const char*>(text.data()), text.size()));
  ASSERT_TRUE(expected.ok()) << expected.status().ToString();
  WebpImageDecoder decoder;
  ASSERT_EQ(expected->object().size(), 2u);
  for (const auto& [name, levels] : expected->object()) {
    for (const std::string& form : {name, name + ".c3d"}) {
      StatusOr<std::unique_ptr<FileSource>> source = OpenPackage((dir / form).string());
      ASSERT_TRUE(source.ok()) << source.status().ToString();
      for (size_t level = 0; level < levels.array().size(); ++level) {
        ReadOptions read;
        read.level = static_cast<int>(level);
        StatusOr<TwoLayerPanorama> pano = ReadPackage(**source, decoder, read);
        ASSERT_TRUE(pano.ok()) << form << ": " << pano.status().ToString();
        const Value got = Summary(*pano);
        const Value& want = levels.array()[level];
        SCOPED_TRACE(form + " level " + std::to_string(level));
        EXPECT_EQ(*got.Find("width"), *want.Find("width"));
        EXPECT_EQ(*got.Find("present"), *want.Find("present"));
        EXPECT_EQ(*got.Find("rgb_sum"), *want.Find("rgb_sum"));
        EXPECT_EQ(got.Find("graph_sha256")->string_value(), want.Find("graph_sha256")->string_value());
        for (int l = 0; l < kNumLayers; ++l) {
          const double d = want.Find("depth_sum_m")->array()[l].number_value();
          EXPECT_NEAR(got.Find("depth_sum_m")->array()[l].number_value(), d, 1e-6 * d + 1e-9);
          for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(got.Find("normal_sum")->array()[l].array()[c].number_value(),
                        want.Find("normal_sum")->array()[l].array()[c].number_value(), 1e-3);
        }
      }
    }
  }
}

TEST(PackageVectorsTest, InvalidVectorsAreRefused) {
  const fs::path dir = VectorsDir() / "invalid";
  if (!fs::exists(dir)) GTEST_SKIP() << "no " << dir;
  WebpImageDecoder decoder;
  int count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    FolderFileSource source(entry.path().string());
    StatusOr<TwoLayerPanorama> pano = ReadPackage(source, decoder);
    EXPECT_FALSE(pano.ok()) << entry.path() << " was accepted";
    ++count;
  }
  EXPECT_EQ(count, 6);
}

}  // namespace
}  // namespace casual3d::encoder
