#include "encoder/package_writer.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>

#include <gtest/gtest.h>

#include "base/testing/scratch_dir.h"
#include "encoder/level_of_detail.h"
#include "encoder/webp_codec.h"
#include "format/file_source.h"
#include "format/package_reader.h"
#include "format/package_test_scene.h"

namespace casual3d::encoder {
namespace {

namespace fs = std::filesystem;

class PackageWriterTest : public casual3d::testing::TestWithScratchDir {
 protected:
  void SetUp() override {
    pano_ = casual3d::testing::MakePackageTestPanorama(512, 256);
    options_.tile_size = 128;
    options_.levels = 3;
    options_.num_threads = 2;
  }

  PackageFiles Encode(PackageStats* stats = nullptr) {
    StatusOr<PackageFiles> files = EncodePackage(pano_, options_, stats);
    EXPECT_TRUE(files.ok()) << files.status().ToString();
    return files.ok() ? *files : PackageFiles();
  }

  // Reads each of the first `levels` levels of `files` and calls `check`
  // with the level, the manifest, what it should hold (pano_ halved as the
  // encoder halves it) and what was decoded.
  void ForEachDecodedLevel(const PackageFiles& files, int levels,
                           const std::function<void(int, const Manifest&, const TwoLayerPanorama&,
                                                    const TwoLayerPanorama&)>& check) {
    MemoryFileSource source;
    for (const auto& [path, bytes] : files) source.Add(path, bytes);
    TwoLayerPanorama expected = pano_;
    for (int level = 0; level < levels; ++level) {
      ReadOptions read;
      read.level = level;
      Manifest manifest;
      StatusOr<TwoLayerPanorama> decoded = ReadPackage(source, decoder_, read, &manifest);
      ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
      check(level, manifest, expected, *decoded);
      if (level + 1 < levels) expected = *HalvePanorama(expected);
    }
  }

  TwoLayerPanorama pano_;
  PackageOptions options_;
  WebpImageDecoder decoder_;
};

double ColorPsnr(const TwoLayerPanorama& a, const TwoLayerPanorama& b) {
  double se = 0;
  size_t n = 0;
  for (int l = 0; l < kNumLayers; ++l)
    for (size_t i = 0; i < a.layer(l).present.size(); ++i) {
      if (!a.layer(l).present[i]) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = double(a.layer(l).rgb[3 * i + c]) - b.layer(l).rgb[3 * i + c];
        se += d * d;
        ++n;
      }
    }
  return 10 * std::log10(255.0 * 255.0 / (se / n));
}

// Graph exact, depth within the encoding's bound, normals within
// `max_angle_deg` (1 degree for 8-bit codes).
void ExpectDecodedMatches(const TwoLayerPanorama& expected, const TwoLayerPanorama& decoded,
                          const DepthQuantization& q, double min_psnr,
                          double max_angle_deg = 1.0) {
  ASSERT_EQ(decoded.width(), expected.width());
  ASSERT_EQ(decoded.height(), expected.height());
  const double bound = q.MaxRelativeError() * 1.01 + 1e-7;
  double worst_depth = 0, worst_angle = 0;
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& E = expected.layer(l);
    const LayerData& D = decoded.layer(l);
    ASSERT_EQ(E.present, D.present);
    ASSERT_EQ(E.label, D.label);
    ASSERT_EQ(E.links, D.links);
    for (size_t i = 0; i < E.present.size(); ++i) {
      if (!E.present[i]) continue;
      worst_depth = std::max(worst_depth, std::fabs(D.depth_m[i] / E.depth_m[i] - 1.0));
      double dot = 0, ne = 0;
      for (int c = 0; c < 3; ++c) {
        dot += double(E.normal[3 * i + c]) * D.normal[3 * i + c];
        ne += double(E.normal[3 * i + c]) * E.normal[3 * i + c];
      }
      if (ne == 0) {
        ASSERT_EQ(D.normal[3 * i] + D.normal[3 * i + 1] + D.normal[3 * i + 2], 0.0f);
        continue;
      }
      worst_angle = std::max(worst_angle, std::acos(std::fmin(1.0, dot)) * 180 / M_PI);
    }
  }
  EXPECT_LE(worst_depth, bound);
  EXPECT_LT(worst_angle, max_angle_deg);
  EXPECT_GT(ColorPsnr(expected, decoded), min_psnr);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(decoded.frame().rotation[i], expected.frame().rotation[i]);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(decoded.frame().centre[i], expected.frame().centre[i]);
}

// Mean and 99th percentile (nearest rank) of the angle, degrees, between
// the lit present nodes' normals of `expected` and `decoded`.
struct NormalAngles {
  double mean_deg = 0, p99_deg = 0;
};
NormalAngles NormalAnglesOf(const TwoLayerPanorama& expected, const TwoLayerPanorama& decoded) {
  std::vector<double> angles;
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& E = expected.layer(l);
    const LayerData& D = decoded.layer(l);
    for (size_t i = 0; i < E.present.size(); ++i) {
      const float* e = &E.normal[3 * i];
      if (!E.present[i] || (e[0] == 0 && e[1] == 0 && e[2] == 0)) continue;
      const double dot = double(e[0]) * D.normal[3 * i] + double(e[1]) * D.normal[3 * i + 1] +
                         double(e[2]) * D.normal[3 * i + 2];
      angles.push_back(std::acos(std::fmin(1.0, dot)) * 180 / M_PI);
    }
  }
  NormalAngles a;
  if (angles.empty()) return a;
  for (double v : angles) a.mean_deg += v / angles.size();
  std::sort(angles.begin(), angles.end());
  a.p99_deg = angles[static_cast<size_t>(std::ceil(0.99 * angles.size())) - 1];
  return a;
}

TEST_F(PackageWriterTest, FolderRoundTripAtEveryLevel) {
  PackageStats stats;
  const PackageFiles files = Encode(&stats);
  ASSERT_EQ(files.front().first, "manifest.json");
  EXPECT_EQ(stats.level_bytes.size(), 3u);
  EXPECT_EQ(stats.num_files, 1 + 4 * (4 * 2 + 2 * 1 + 1 * 1));
  EXPECT_LT(stats.level_bytes[2], stats.level_bytes[0] / 4);
  const std::string dir = (dir_ / "pkg").string();
  ASSERT_TRUE(WritePackageFolder(files, dir).ok());
  FolderFileSource source(dir);
  TwoLayerPanorama expected = pano_;
  for (int level = 0; level < 3; ++level) {
    ReadOptions read;
    read.level = level;
    read.num_threads = 2;
    Manifest manifest;
    StatusOr<TwoLayerPanorama> decoded = ReadPackage(source, decoder_, read, &manifest);
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    EXPECT_NEAR(manifest.depth.near_m, 2.0, 0.01);
    EXPECT_NEAR(manifest.depth.far_m, 100.0, 1e-9);
    // Coarser levels hold more detail per pixel, which lossy coding keeps less well.
    const double min_psnr[3] = {37.5, 35.5, 33.5};
    ExpectDecodedMatches(expected, *decoded, manifest.depth, min_psnr[level]);
    std::printf("level %d: colour PSNR %.2f dB\n", level, ColorPsnr(expected, *decoded));
    if (level < 2) expected = *HalvePanorama(expected);
  }
  // Rewriting over an existing package replaces it; no temporary folder is left.
  ASSERT_TRUE(WritePackageFolder(files, dir).ok());
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir_)) entries += 1 + 0 * e.is_directory();
  EXPECT_EQ(entries, 1);
}

// A level left out (package 2.0): the others decode to the levels of the
// package with every level, under the next level numbers, from the same
// colour, depth and normal files and smaller graph images (right and down
// links only); the level may not be level 0 or the coarsest.
TEST_F(PackageWriterTest, OmittedLevelLeavesTheOthersAsTheyWere) {
  options_.levels = 4;  // 512, 256, 128 and 64 pixels wide.
  PackageStats all_stats;
  const PackageFiles all = Encode(&all_stats);
  options_.omit_level_width = 256;
  PackageStats stats;
  const PackageFiles files = Encode(&stats);
  MemoryFileSource source, all_source;
  for (const auto& [path, bytes] : files) source.Add(path, bytes);
  for (const auto& [path, bytes] : all) all_source.Add(path, bytes);
  StatusOr<Manifest> manifest = ReadManifest(source);
  ASSERT_TRUE(manifest.ok()) << manifest.status().ToString();
  EXPECT_EQ(manifest->version_major, 2);
  EXPECT_EQ(manifest->version_minor, 0);
  ASSERT_EQ(manifest->levels.size(), 3u);
  ASSERT_EQ(stats.level_bytes.size(), 3u);
  const int widths[3] = {512, 128, 64};
  for (int l = 0; l < 3; ++l) EXPECT_EQ(manifest->levels[l].width, widths[l]);
  EXPECT_LT(stats.level_bytes[0], all_stats.level_bytes[0]);
  EXPECT_LT(stats.level_bytes[1], all_stats.level_bytes[2]);
  std::map<std::string, const std::vector<uint8_t>*> all_files;
  for (const auto& [path, bytes] : all) all_files[path] = &bytes;
  uint64_t graph_bytes = 0, all_graph_bytes = 0;
  for (const auto& [path, bytes] : files) {
    if (path == kManifestFileName) continue;
    const int level = path[1] - '0';
    const std::string same = "l" + std::to_string(level == 0 ? 0 : level + 1) + path.substr(2);
    ASSERT_EQ(all_files.count(same), 1u) << same;
    if (path.find(".graph.") == std::string::npos) {
      EXPECT_TRUE(*all_files[same] == bytes) << path;
    } else {
      graph_bytes += bytes.size();
      all_graph_bytes += all_files[same]->size();
    }
  }
  EXPECT_LT(graph_bytes, all_graph_bytes);
  for (int level = 0; level < 3; ++level) {
    ReadOptions read, all_read;
    read.level = level;
    all_read.level = level == 0 ? 0 : level + 1;
    StatusOr<TwoLayerPanorama> decoded = ReadPackage(source, decoder_, read);
    StatusOr<TwoLayerPanorama> all_decoded = ReadPackage(all_source, decoder_, all_read);
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    ASSERT_TRUE(all_decoded.ok()) << all_decoded.status().ToString();
    EXPECT_TRUE(*decoded == *all_decoded) << "level " << level;
  }
  // Colour alone encoded again needs an earlier encoding of the same levels.
  const StatusOr<PackageFiles> mixed = ReencodeColor(pano_, options_, all);
  EXPECT_EQ(mixed.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(mixed.status().message().find("other levels"), std::string::npos);
  PackageOptions lower = options_;
  lower.color_quality = 70;
  PackageStats reencoded;
  ASSERT_TRUE(ReencodeColor(pano_, lower, files, &reencoded).ok());
  EXPECT_LT(reencoded.total_bytes, stats.total_bytes);
  // Any width in [256, 511] names the 256 level (it lies in (W/2, W]).
  options_.omit_level_width = 300;
  PackageStats wider;
  Encode(&wider);
  EXPECT_EQ(wider.level_bytes, stats.level_bytes);
  // Level 0 and the coarsest level are never left out, nor one that no
  // level's width is in (W/2, W] for: then it is 1.0.
  for (int width : {512, 64, 100, 1023}) {
    options_.omit_level_width = width;
    PackageStats kept;
    const PackageFiles again = Encode(&kept);
    EXPECT_EQ(kept.level_bytes, all_stats.level_bytes) << width;
    const std::string text(again.front().second.begin(), again.front().second.end());
    EXPECT_NE(text.find("\"version\": \"1.0\""), std::string::npos) << width;
  }
}

// The largest angle between a unit normal and its decoded `bits`-bit
// octahedral code, over a dense spiral of normals.
double WorstOctahedralErrorDeg(int bits) {
  NormalQuantization q;
  q.bits = bits;
  double worst = 0;
  constexpr int kSamples = 2000000;
  for (int k = 0; k < kSamples; ++k) {
    const double z = 1 - (2 * k + 1.0) / kSamples, r = std::sqrt(1 - z * z);
    const double phi = k * M_PI * (3 - std::sqrt(5.0));
    const float n[3] = {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)};
    uint8_t code[2];
    float d[3];
    EncodeOctahedral(n, q, code);
    EXPECT_TRUE(DecodeOctahedral(code, q, d));
    const double dot = double(n[0]) * d[0] + double(n[1]) * d[1] + double(n[2]) * d[2];
    worst = std::max(worst, std::acos(std::fmin(1.0, dot)) * 180 / M_PI);
  }
  return worst;
}

TEST(DeliveryPackageOptionsTest, NormalBoundOfFiveBitCodes) {
  // DeliveryPackageOptions() declares 5-bit normals within 8.1 degrees.
  const double worst5 = WorstOctahedralErrorDeg(5);
  std::printf("largest angular error: 5 bits %.2f deg, 8 bits %.2f deg\n", worst5,
              WorstOctahedralErrorDeg(8));
  EXPECT_LT(worst5, 8.1);
  EXPECT_GT(worst5, 7.5);  // Not far from the bound: the bound is tight.
}

TEST_F(PackageWriterTest, DeliveryOptionsKeepTheirBoundsAndShrinkThePackage) {
  PackageStats exact_stats, delivery_stats;
  Encode(&exact_stats);
  const PackageOptions exact = options_;
  options_ = DeliveryPackageOptions();
  options_.tile_size = exact.tile_size;
  options_.levels = exact.levels;
  options_.num_threads = exact.num_threads;
  ASSERT_TRUE(options_.Check().ok());
  const PackageFiles files = Encode(&delivery_stats);
  EXPECT_LT(delivery_stats.total_bytes, exact_stats.total_bytes * 3 / 4);
  EXPECT_TRUE(options_.fill_absent);
  ForEachDecodedLevel(files, 3, [](int level, const Manifest& manifest,
                                    const TwoLayerPanorama& expected,
                                    const TwoLayerPanorama& decoded) {
    EXPECT_FALSE(manifest.normal.lossy());
    EXPECT_EQ(manifest.normal.bits, 5);
    EXPECT_EQ(manifest.depth.bits, 9);
    // Depth within exp(ln(50) / 1020) - 1 = 0.38% (the bound of 9-bit codes).
    EXPECT_NEAR(manifest.depth.MaxRelativeError(), std::exp(std::log(50.0) / 1020) - 1, 1e-5);
    const double min_psnr[3] = {37.5, 35.5, 33.5};
    ExpectDecodedMatches(expected, decoded, manifest.depth, min_psnr[level], 8.1);
  });
}

TEST_F(PackageWriterTest, LossyNormalsKeepTheirBoundsAtEveryLevel) {
  options_ = DeliveryPackageOptions();
  options_.lossy_normals = true;
  options_.tile_size = 64;
  options_.levels = 3;
  options_.num_threads = 2;
  PackageStats stats;
  const PackageFiles files = Encode(&stats);
  ForEachDecodedLevel(files, 3, [](int level, const Manifest& manifest,
                                    const TwoLayerPanorama& expected,
                                    const TwoLayerPanorama& decoded) {
    EXPECT_EQ(manifest.version_minor, 2);
    EXPECT_TRUE(manifest.normal.lossy());
    EXPECT_EQ(manifest.normal.mean_error_deg, 2.5);
    EXPECT_EQ(manifest.normal.p99_error_deg, 9.0);
    // Each tile keeps both bounds, so the level does; single nodes may be
    // further off, and unlit nodes stay unlit (ExpectDecodedMatches).
    ExpectDecodedMatches(expected, decoded, manifest.depth, 33.5, 180.0);
    const NormalAngles angles = NormalAnglesOf(expected, decoded);
    EXPECT_LE(angles.mean_deg, 2.5) << level;
    EXPECT_LE(angles.p99_deg, 9.0) << level;
    EXPECT_GT(angles.mean_deg, 0.1) << level;
  });
}

// Bytes of the tile files whose name ends in `suffix`.
uint64_t BytesOfKind(const PackageFiles& files, const std::string& suffix) {
  uint64_t sum = 0;
  for (const auto& [path, bytes] : files)
    if (path.size() > suffix.size() &&
        path.compare(path.size() - suffix.size(), suffix.size(), suffix) == 0)
      sum += bytes.size();
  return sum;
}

TEST_F(PackageWriterTest, FilledAbsentNodesDecodeToTheSamePanoramaInFewerBytes) {
  const PackageFiles zeros = Encode();
  options_.fill_absent = true;
  const PackageFiles filled = Encode();
  // The back layer is a disc: its depth and normal tiles hold edges between
  // present and absent nodes, which filling makes cheaper (here by 2-3%, the
  // codes being smooth; 5-7% on reconstructions).
  for (const char* kind : {".depth.webp", ".normal.webp"})
    EXPECT_LT(BytesOfKind(filled, kind), BytesOfKind(zeros, kind) * 99 / 100) << kind;
  EXPECT_EQ(BytesOfKind(filled, ".graph.webp"), BytesOfKind(zeros, ".graph.webp"));
  // Every absent back node of the filled depth tile of level 0, row 0, column
  // 1 (beside the centre, holding part of the disc) carries a code.
  const std::vector<uint8_t>* depth_tile = nullptr;
  for (const auto& [path, bytes] : filled)
    if (path == "l0/0-1.depth.webp") depth_tile = &bytes;
  ASSERT_NE(depth_tile, nullptr);
  StatusOr<Image8> image = DecodeWebp(depth_tile->data(), depth_tile->size());
  ASSERT_TRUE(image.ok()) << image.status().ToString();
  int absent = 0, absent_with_code = 0;
  for (int y = 0; y < options_.tile_size; ++y)
    for (int x = 0; x < options_.tile_size; ++x) {
      if (pano_.present(kBack, options_.tile_size + x, y)) continue;
      ++absent;
      const uint8_t* px = &image->at(x, options_.tile_size + y);
      absent_with_code += (px[0] | px[1]) != 0;
    }
  ASSERT_GT(absent, 0);
  EXPECT_EQ(absent_with_code, absent);
  // Every level decodes to exactly what the zero-filled package gives.
  MemoryFileSource zero_source, filled_source;
  for (const auto& [path, bytes] : zeros) zero_source.Add(path, bytes);
  for (const auto& [path, bytes] : filled) filled_source.Add(path, bytes);
  for (int level = 0; level < 3; ++level) {
    ReadOptions read;
    read.level = level;
    StatusOr<TwoLayerPanorama> a = ReadPackage(zero_source, decoder_, read);
    StatusOr<TwoLayerPanorama> b = ReadPackage(filled_source, decoder_, read);
    ASSERT_TRUE(a.ok() && b.ok());
    for (int l = 0; l < kNumLayers; ++l) {
      EXPECT_EQ(a->layer(l).present, b->layer(l).present);
      EXPECT_EQ(a->layer(l).links, b->layer(l).links);
      EXPECT_EQ(a->layer(l).depth_m, b->layer(l).depth_m);
      EXPECT_EQ(a->layer(l).normal, b->layer(l).normal);
      EXPECT_EQ(a->layer(l).rgb, b->layer(l).rgb);
    }
  }
}

TEST_F(PackageWriterTest, SingleFileGivesTheSamePanorama) {
  const PackageFiles files = Encode();
  const std::string path = (dir_ / "scene.c3d").string();
  ASSERT_TRUE(WritePackageSingleFile(files, path).ok());
  ASSERT_TRUE(WritePackageFolder(files, (dir_ / "pkg").string()).ok());
  std::ifstream in(path, std::ios::binary);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  StatusOr<std::unique_ptr<SingleFileSource>> single = SingleFileSource::Create(bytes);
  ASSERT_TRUE(single.ok()) << single.status().ToString();
  StatusOr<TwoLayerPanorama> a = ReadPackage(**single, decoder_);
  StatusOr<TwoLayerPanorama> b = ReadPackage(FolderFileSource((dir_ / "pkg").string()), decoder_);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_TRUE(*a == *b);
}

TEST_F(PackageWriterTest, CorruptPackagesGiveClearErrors) {
  const PackageFiles files = Encode();
  auto read_with = [&](const std::string& path, const std::vector<uint8_t>* replacement) {
    MemoryFileSource source;
    for (const auto& [p, bytes] : files)
      if (p != path || replacement != nullptr) source.Add(p, p == path ? *replacement : bytes);
    return ReadPackage(source, decoder_).status();
  };
  const std::string tile = files[5].first;
  // Missing file.
  Status missing = read_with(tile, nullptr);
  EXPECT_EQ(missing.code(), StatusCode::kNotFound);
  EXPECT_NE(missing.message().find(tile), std::string::npos);
  // Flipped byte: checksum.
  std::vector<uint8_t> flipped = files[5].second;
  flipped[flipped.size() / 2] ^= 1;
  Status corrupt = read_with(tile, &flipped);
  EXPECT_EQ(corrupt.code(), StatusCode::kInvalidData);
  EXPECT_NE(corrupt.message().find("SHA-256"), std::string::npos);
  // Truncated file.
  std::vector<uint8_t> cut(files[5].second.begin(), files[5].second.end() - 10);
  EXPECT_EQ(read_with(tile, &cut).code(), StatusCode::kInvalidData);
  // A manifest path that tries to leave the package.
  std::string manifest(files[0].second.begin(), files[0].second.end());
  const size_t at = manifest.find("\"l0/0-0.color.webp\"");
  ASSERT_NE(at, std::string::npos);
  manifest.replace(at, 19, "\"../0-0.color.webp\"");
  std::vector<uint8_t> evil(manifest.begin(), manifest.end());
  Status escape = read_with("manifest.json", &evil);
  EXPECT_EQ(escape.code(), StatusCode::kInvalidData);
  EXPECT_NE(escape.message().find("safe relative path"), std::string::npos) << escape.ToString();
}

TEST_F(PackageWriterTest, RefusesBadOptionsAndUnrelatedFolders) {
  options_.tile_size = 8;
  EXPECT_EQ(EncodePackage(pano_, options_).status().code(), StatusCode::kInvalidArgument);
  options_.tile_size = 128;
  options_.omit_level_width = -1;
  EXPECT_EQ(EncodePackage(pano_, options_).status().message(),
            "omit_level_width -1 is negative (0 writes every level)");
  options_.omit_level_width = 0;
  options_.levels = 8;  // 520 is not divisible by 128.
  Status s = EncodePackage(casual3d::testing::MakePackageTestPanorama(520, 260), options_).status();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("divisible"), std::string::npos);
  options_.levels = 0;
  const PackageFiles files = Encode();
  const fs::path other = dir_ / "photos";
  fs::create_directories(other);
  std::ofstream(other / "keep.jpg") << "x";
  EXPECT_EQ(WritePackageFolder(files, other.string()).code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(fs::exists(other / "keep.jpg"));
}

}  // namespace
}  // namespace casual3d::encoder
