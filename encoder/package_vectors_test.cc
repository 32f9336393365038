// Conformance vectors of spec/package.md Sec. 9 (spec/vectors/): checks that
// every valid vector decodes to the values and meshes in expected.json and
// that every invalid vector breaks exactly the rule it names. With
// CASUAL3D_UPDATE_VECTORS=1 in the environment it first (re)writes the
// vectors from procedural panoramas. What each refusal says
// (spec/vectors/refusals.json) is checked for every reader by
// tests/conformance_test.cc.

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "encoder/package_writer.h"
#include "encoder/webp_codec.h"
#include "format/file_source.h"
#include "format/json.h"
#include "format/mesh_builder.h"
#include "format/mesh_simplify.h"
#include "format/package_reader.h"
#include "format/reader_checks.h"
#include "format/single_file.h"
#include "format/package_test_scene.h"
#include "format/sha256.h"
#include "format/testing/graph_digest.h"
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
  }
  level.Set("present", std::move(present));
  level.Set("rgb_sum", std::move(rgb));
  level.Set("depth_sum_m", std::move(depth));
  level.Set("normal_sum", std::move(normal));
  level.Set("graph_sha256", Value::String(casual3d::testing::GraphSha256Hex(pano)));
  return level;
}

std::vector<uint8_t> ReadBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void WriteBytes(const fs::path& p, const std::vector<uint8_t>& b) {
  std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(b.data()),
                                          static_cast<std::streamsize>(b.size()));
}

// The mesh members of expected.json (spec/package.md Sec. 9): vertex and
// triangle counts and the SHA-256 of positions, normals, uvs (float32) and
// indices (uint32), each array little-endian, in that order.
Value MeshSummary(const Mesh& mesh) {
  std::vector<uint8_t> bytes;
  auto put = [&bytes](uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<uint8_t>(v >> (8 * i)));
  };
  for (const std::vector<float>* a : {&mesh.positions, &mesh.normals, &mesh.uvs}) {
    for (float f : *a) {
      uint32_t u;
      std::memcpy(&u, &f, 4);
      put(u);
    }
  }
  for (uint32_t i : mesh.indices) put(i);
  Value v = Value::Object();
  v.Set("vertices", Value::Number(static_cast<double>(mesh.num_vertices())));
  v.Set("triangles", Value::Number(static_cast<double>(mesh.num_triangles())));
  v.Set("sha256", Value::String(Sha256Hex(bytes.data(), bytes.size())));
  return v;
}

// The two simplification settings of spec/package.md Sec. 9.
constexpr double kSimplifyErrors[] = {0.01, 0.05};

// The full mesh and the simplified meshes of a decoded level.
Value Meshes(const TwoLayerPanorama& pano) {
  Value meshes = Value::Object();
  MeshBuildOptions build;
  build.num_threads = 1;
  StatusOr<Mesh> full = BuildMesh(pano, build);
  EXPECT_TRUE(full.ok()) << full.status().ToString();
  if (!full.ok()) return meshes;
  meshes.Set("full", MeshSummary(*full));
  Value simplified = Value::Array();
  for (double error : kSimplifyErrors) {
    MeshSimplifyOptions options;
    options.max_triangles = 0;
    options.max_relative_error = error;
    options.num_threads = 1;
    StatusOr<SimplifiedMesh> s = BuildSimplifiedMesh(pano, options);
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    if (!s.ok()) return meshes;
    Value v = MeshSummary(s->mesh);
    v.Set("max_relative_error", Value::Number(error));
    simplified.Append(std::move(v));
  }
  meshes.Set("simplified", std::move(simplified));
  return meshes;
}

// The test panorama with links between the layers and labels across them: where
// a back node's right neighbour has only a front node, the back node links to
// it instead of the front node of its own pixel (the back layer joining the
// front background where it emerges from behind the object); front nodes of
// the ring around the object in even columns are labelled B, back nodes in
// every third column F.
TwoLayerPanorama CrossLayerPanorama(int width, int height, uint32_t seed, int* cross_links) {
  TwoLayerPanorama pano = casual3d::testing::MakePackageTestPanorama(width, height, seed);
  LayerData& F = pano.layer(kFront);
  LayerData& B = pano.layer(kBack);
  *cross_links = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      int qx, qy;
      pano.Neighbour(x, y, kRight, &qx, &qy);
      const size_t p = pano.index(x, y), q = pano.index(qx, qy);
      if (!B.present[p] || B.present[q] || !F.present[q]) continue;
      if (GetLink(F.links[p], kRight) != Link::kFront || GetLink(B.links[p], kRight) != Link::kNone)
        continue;
      F.links[p] = SetLink(F.links[p], kRight, Link::kNone);
      B.links[p] = SetLink(B.links[p], kRight, Link::kFront);
      F.links[q] = SetLink(F.links[q], kLeft, Link::kBack);
      ++*cross_links;
    }
  }
  for (size_t i = 0; i < F.present.size(); ++i) {
    const int x = static_cast<int>(i % width);
    if (F.present[i] && B.present[i] && x % 2 == 0) F.label[i] = 1;
    if (B.present[i] && x % 3 == 0) B.label[i] = 0;
  }
  return pano;
}

// Replaces a file of a package and fixes its manifest entry, so that only the
// file's content differs.
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

// Replaces the first occurrence of `from` in the manifest by `to`.
PackageFiles WithManifest(PackageFiles files, const std::string& from, const std::string& to) {
  std::string manifest(files[0].second.begin(), files[0].second.end());
  EXPECT_NE(manifest.find(from), std::string::npos) << from;
  manifest.replace(manifest.find(from), from.size(), to);
  files[0].second.assign(manifest.begin(), manifest.end());
  return files;
}

// Applies `edit` to the parsed manifest and writes it back as the writer does.
template <typename Edit>
PackageFiles EditManifest(PackageFiles files, Edit edit) {
  const std::vector<uint8_t>& m = files[0].second;
  Value root = *json::Parse(std::string_view(reinterpret_cast<const char*>(m.data()), m.size()));
  edit(&root);
  const std::string text = json::Serialize(root, 2) + "\n";
  files[0].second.assign(text.begin(), text.end());
  return files;
}

const std::vector<uint8_t>& FileBytes(const PackageFiles& files, const std::string& path) {
  for (const auto& [p, b] : files)
    if (p == path) return b;
  ADD_FAILURE() << "no " << path;
  return files[0].second;
}

// A tile image decoded, changed by `edit` and encoded again (lossless unless
// `lossy`) in place of the original.
template <typename Edit>
PackageFiles EditTileImage(const PackageFiles& files, const std::string& path, Edit edit,
                           bool lossy = false) {
  const std::vector<uint8_t>& bytes = FileBytes(files, path);
  Image8 image = *DecodeWebp(bytes.data(), bytes.size());
  edit(&image);
  WebpEncodeOptions options;
  options.lossless = !lossy;
  options.quality = 100;
  const Image8& c = image;
  return ReplaceFile(files, path, *EncodeWebp(c.view(), options));
}

// `from` replaced by `to` (of the same length) in a container's directory.
std::vector<uint8_t> PatchDirectory(std::vector<uint8_t> c, const std::string& from,
                                    const std::string& to) {
  auto at = std::search(c.begin(), c.end(), from.begin(), from.end());
  EXPECT_TRUE(at != c.end() && from.size() == to.size()) << from;
  if (at != c.end()) std::copy(to.begin(), to.end(), at);
  return c;
}

struct InvalidVector {
  std::string name;                // Its check's name.
  PackageFiles files;              // Folder form, unless empty.
  std::vector<uint8_t> container;  // .c3d form, unless empty.
};

// Invalid vectors (spec/package.md Sec. 9), each breaking exactly one rule of
// a valid vector: `base` (two-layer-64x32), `deep` (front-only-48x24, 16-bit
// depth codes, for the lossy tile whose changed codes stay valid) or `v2`
// (level-left-out-64x32, for the rules of version 2.x).
std::vector<InvalidVector> MakeInvalidVectors(const PackageFiles& base, const PackageFiles& deep,
                                              const PackageFiles& v2) {
  const std::string graph = "l0/0-1.graph.webp", depth = "l0/0-1.depth.webp";
  const std::string normal = "l0/0-1.normal.webp", color = "l0/0-1.color.webp";
  auto container = [](const PackageFiles& files) { return *BuildSingleFile(files); };
  // A front node of tile 0-1 (pixels 16..31 x 0..15) that links right to the
  // front node beside it, in the tile's image coordinates.
  const int lx = 4, ly = 8;
  std::vector<InvalidVector> v;
  auto both = [&](const std::string& name, PackageFiles files) {
    std::vector<uint8_t> c = container(files);
    v.push_back({name, std::move(files), std::move(c)});
  };
  both("unknown-major", WithManifest(base, "\"version\": \"1.0\"", "\"version\": \"3.0\""));
  both("nesting-too-deep", EditManifest(base, [](Value* root) {
         Value nested = Value::Array();  // 16 arrays in the root object: depth 17.
         for (int i = 1; i < kMaxManifestNesting; ++i) {
           Value outer = Value::Array();
           outer.Append(std::move(nested));
           nested = std::move(outer);
         }
         root->Set("x_nest", std::move(nested));
       }));
  both("near-equals-far", EditManifest(base, [](Value* root) {
         Value depth_encoding = *root->Find("depth_encoding");
         depth_encoding.Set("far_m", *depth_encoding.Find("near_m"));
         root->Set("depth_encoding", std::move(depth_encoding));
       }));
  {
    // "l0/../l0/0-1.graph.webp" names the same file but has a ".." component.
    const std::string escape = "l0/../l0/" + graph.substr(3), placeholder = "l0/xx/l0/" + graph.substr(3);
    PackageFiles files = EditManifest(base, [&](Value* root) {
      Value files_value = *root->Find("files");
      for (Value& f : files_value.array())
        if (f.Find("path")->string_value() == graph) f.Set("path", Value::String(escape));
      std::sort(files_value.array().begin(), files_value.array().end(), [](const Value& a, const Value& b) {
        return a.Find("path")->string_value() < b.Find("path")->string_value();
      });
      root->Set("files", std::move(files_value));
    });
    files = WithManifest(files, "\"graph\": \"" + graph + "\"", "\"graph\": \"" + escape + "\"");
    PackageFiles renamed = files;
    for (auto& [p, b] : renamed)
      if (p == graph) p = placeholder;
    v.push_back({"path-escape", files, PatchDirectory(container(renamed), placeholder, escape)});
  }
  {
    const std::vector<uint8_t>& b = FileBytes(base, graph);
    both("size-mismatch", EditManifest(base, [&](Value* root) {
           Value files_value = *root->Find("files");
           for (Value& f : files_value.array())
             if (f.Find("path")->string_value() == graph)
               f.Set("bytes", Value::Number(static_cast<double>(b.size() + 1)));
           root->Set("files", std::move(files_value));
         }));
    std::string hash = Sha256Hex(b.data(), b.size()), other = hash;
    other[63] = other[63] == '0' ? '1' : '0';
    both("checksum-mismatch", WithManifest(base, hash, other));
  }
  both("lossy-data-tile", EditTileImage(deep, depth, [](Image8*) {}, /*lossy=*/true));
  both("wrong-tile-size", EditTileImage(base, color, [](Image8* image) {
         Image8 wider(image->width() + 1, image->height(), 3, 0);
         for (int y = 0; y < image->height(); ++y)
           for (int x = 0; x < wider.width(); ++x)
             for (int c = 0; c < 3; ++c)
               wider.at(x, y, c) = image->at(std::min(x, image->width() - 1), y, c);
         *image = std::move(wider);
       }));
  both("reserved-flag-bits",
       EditTileImage(base, graph, [&](Image8* g) { g->at(lx, ly, 2) |= 0x80; }));
  // A left link stored at a present front node: with the check off the bits
  // are dropped and the links completed as in the valid vector.
  both("left-up-link-bits",
       EditTileImage(v2, graph, [&](Image8* g) { g->at(lx, ly, 0) |= 0x10; }));
  both("depth-code-above-max", EditTileImage(base, depth, [&](Image8* d) {
         d->at(lx, ly, 0) = 0x10;  // Code 4096 > 4095 (12 bits).
         d->at(lx, ly, 1) = 0x00;
       }));
  both("normal-code-invalid",
       EditTileImage(base, normal, [&](Image8* n) { n->at(lx, ly, 1) = 0; }));
  both("present-node-without-depth", EditTileImage(base, depth, [&](Image8* d) {
         d->at(lx, ly, 0) = 0;
         d->at(lx, ly, 1) = 0;
       }));
  both("link-not-mutual", EditTileImage(base, graph, [&](Image8* g) {
         // The first front node linked to the front node on its right: that
         // neighbour no longer links back.
         for (int y = 0; y < g->height(); ++y) {
           for (int x = 0; x + 1 < g->width(); ++x) {
             if (GetLink(g->at(x, y, 0), kRight) != Link::kFront) continue;
             g->at(x + 1, y, 0) = SetLink(g->at(x + 1, y, 0), kLeft, Link::kNone);
             return;
           }
         }
         ADD_FAILURE() << "no front node links right";
       }));
  // Container rules, .c3d only.
  std::vector<uint8_t> c = container(base);
  v.push_back({"container-unknown-major", {}, [&] {
                 std::vector<uint8_t> b = c;
                 b[8] = 2;
                 return b;
               }()});
  v.push_back({"manifest-not-first", {}, [&] {
                 // Swap the first two directory records (offsets are absolute).
                 std::vector<uint8_t> b = c;
                 const size_t first = 2 + b[16] + 16, second = 2 + b[16 + first] + 16;
                 std::rotate(b.begin() + 16, b.begin() + 16 + first, b.begin() + 16 + first + second);
                 return b;
               }()});
  {
    // An extra entry of the same length renamed to an existing path.
    PackageFiles files = base;
    const std::string twin = graph.substr(0, graph.size() - 1) + "q";
    files.push_back({twin, FileBytes(base, graph)});
    v.push_back({"duplicate-entry", {}, PatchDirectory(container(files), twin, graph)});
    // An entry the manifest does not list, its data range past the end.
    files = base;
    files.push_back({"x_extra.bin", {1, 2, 3, 4}});
    std::vector<uint8_t> b = container(files);
    const std::string extra = "x_extra.bin";
    const size_t at = std::search(b.begin(), b.end(), extra.begin(), extra.end()) - b.begin();
    b[at + extra.size() + 8 + 7] = 0x01;  // Its size becomes 2^56 + 4.
    v.push_back({"entry-outside-file", {}, std::move(b)});
  }
  return v;
}

// Every level of a package; the first failure.
Status ReadAllLevels(const std::string& path, const ReaderChecks& checks) {
  WebpImageDecoder decoder;
  StatusOr<std::unique_ptr<FileSource>> source = OpenPackage(path, 1ull << 31, checks);
  if (!source.ok()) return source.status();
  ReadOptions read;
  read.checks = checks;
  Manifest manifest;
  for (int level = 0, levels = 1; level < levels; ++level) {
    read.level = level;
    StatusOr<TwoLayerPanorama> pano = ReadPackage(**source, decoder, read, &manifest);
    if (!pano.ok()) return pano.status();
    levels = static_cast<int>(manifest.levels.size());
  }
  return Status::Ok();
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
  int cross_links = 0;
  TwoLayerPanorama cross = CrossLayerPanorama(64, 32, 11, &cross_links);
  ASSERT_GT(cross_links, 0);
  // Version 1.2: lossy normals, with a block of unlit (zero-normal) nodes.
  PackageOptions lossy = two_levels;
  lossy.lossy_normals = true;
  TwoLayerPanorama lossy_pano = casual3d::testing::MakePackageTestPanorama(64, 32, 3);
  for (int y = 4; y < 12; ++y)
    for (int x = 40; x < 56; ++x)
      for (int l = 0; l < kNumLayers; ++l)
        std::fill_n(&lossy_pano.layer(l).normal[3 * lossy_pano.index(x, y)], 3, 0.0f);
  // Version 2.0: three levels computed, the middle one (32x16) left out, and
  // graph images of right and down links, front and back nodes linked.
  PackageOptions left_out = two_levels;
  left_out.levels = 3;
  left_out.omit_level_width = 32;
  Vector vectors[] = {
      {"two-layer-64x32", casual3d::testing::MakePackageTestPanorama(64, 32, 3), two_levels},
      {"front-only-48x24", std::move(front_only), one_level},
      {"cross-layer-64x32", std::move(cross), two_levels},
      {"lossy-normals-64x32", std::move(lossy_pano), lossy},
      {"level-left-out-64x32", CrossLayerPanorama(64, 32, 11, &cross_links), left_out},
  };
  std::map<std::string, PackageFiles> encoded;
  for (Vector& v : vectors) {
    ASSERT_TRUE(v.pano.Validate().ok()) << v.name << ": " << v.pano.Validate().ToString();
    StatusOr<PackageFiles> files = EncodePackage(v.pano, v.options);
    ASSERT_TRUE(files.ok()) << files.status().ToString();
    ASSERT_TRUE(WritePackageFolder(*files, (dir / v.name).string()).ok());
    ASSERT_TRUE(WritePackageSingleFile(*files, (dir / (std::string(v.name) + ".c3d")).string()).ok());
    MemoryFileSource source;
    for (const auto& [p, b] : *files) source.Add(p, b);
    StatusOr<Manifest> manifest = ReadManifest(source);
    ASSERT_TRUE(manifest.ok()) << manifest.status().ToString();
    Value levels = Value::Array();
    for (int level = 0; level < static_cast<int>(manifest->levels.size()); ++level) {
      ReadOptions read;
      read.level = level;
      StatusOr<TwoLayerPanorama> pano = ReadPackage(source, decoder, read);
      ASSERT_TRUE(pano.ok()) << pano.status().ToString();
      Value summary = Summary(*pano);
      summary.Set("mesh", Meshes(*pano));
      levels.Append(std::move(summary));
    }
    expected.Set(v.name, std::move(levels));
    encoded[v.name] = *files;
  }
  const std::string text = json::Serialize(expected, 2) + "\n";
  WriteBytes(dir / "expected.json", std::vector<uint8_t>(text.begin(), text.end()));

  fs::remove_all(dir / "invalid");
  for (const InvalidVector& v :
       MakeInvalidVectors(encoded["two-layer-64x32"], encoded["front-only-48x24"],
                          encoded["level-left-out-64x32"])) {
    if (!v.files.empty()) {
      // path-escape keeps the graph file under its own name, which its
      // manifest's "l0/../l0/..." path also reaches.
      for (const auto& [p, b] : v.files) {
        fs::create_directories((dir / "invalid" / v.name / p).parent_path());
        WriteBytes(dir / "invalid" / v.name / p, b);
      }
    }
    WriteBytes(dir / "invalid" / (v.name + ".c3d"), v.container);
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
  ASSERT_EQ(expected->object().size(), 5u);
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
        ASSERT_NE(want.Find("mesh"), nullptr);
        EXPECT_EQ(Meshes(*pano), *want.Find("mesh"));
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

// Every invalid vector, folder and .c3d form, is refused with every check on
// and read (every level) with only the check it names off: it breaks exactly
// that rule.
TEST(PackageVectorsTest, InvalidVectorsBreakExactlyTheirOwnRule) {
  const fs::path dir = VectorsDir() / "invalid";
  if (!fs::exists(dir)) GTEST_SKIP() << "no " << dir;
  std::set<std::string> folders, containers;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().stem().string();
    ReaderCheck check;
    ASSERT_TRUE(ReaderCheckFromName(name, &check)) << entry.path() << " names no reader check";
    SCOPED_TRACE(entry.path().string());
    const Status all = ReadAllLevels(entry.path().string(), ReaderChecks());
    EXPECT_FALSE(all.ok()) << "accepted with every check on";
    EXPECT_GT(all.message().size(), 10u);
    const Status own_off = ReadAllLevels(entry.path().string(), ReaderChecks::AllBut(check));
    EXPECT_TRUE(own_off.ok()) << "refused with " << name << " off: " << own_off.ToString();
    (entry.path().extension() == ".c3d" ? containers : folders).insert(name);
  }
  // Every check has a .c3d vector; those not about the container a folder too.
  EXPECT_EQ(containers.size(), static_cast<size_t>(kNumReaderChecks));
  EXPECT_EQ(folders.size(), static_cast<size_t>(kNumReaderChecks - 4));
  for (const std::string& name : folders) EXPECT_EQ(containers.count(name), 1u) << name;
}

}  // namespace
}  // namespace casual3d::encoder
