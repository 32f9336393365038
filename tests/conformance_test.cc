// Reader conformance (spec/package.md Sec. 9.1): every vector of spec/vectors,
// valid and invalid, as a folder and as a .c3d file, through the three
// readers casual3d ships:
//   - the native reader (format/: OpenPackage, ReadPackage with libwebp),
//   - the wasm reader in Node (the npm package's format entry as built,
//     tests/conformance/wasm_read.mjs),
//   - `casual3d validate`.
// Each must read every level of a valid vector as expected.json says (size,
// present nodes, graph_sha256; the CLI prints sizes and node counts), and
// refuse every invalid vector with a message holding the words
// spec/vectors/refusals.json gives for it (the rule it breaks and the file at
// fault), naming a file of the package, without a doubled "level N:" prefix
// and without any for a problem of manifest.json. Before that, the spec's table,
// the vectors on disk, refusals.json and the reader checks
// (format/reader_checks.h) must name the same rules.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "encoder/webp_codec.h"
#include "format/file_source.h"
#include "format/json.h"
#include "format/package_reader.h"
#include "format/reader_checks.h"
#include "format/testing/graph_digest.h"
#include "tests/casual3d_cli.h"
#include "tests/conformance/spec_table.h"

namespace casual3d {
namespace {

namespace fs = std::filesystem;

fs::path SourceDir() {
  const char* dir = std::getenv("CASUAL3D_SOURCE_DIR");
  return dir != nullptr ? dir : ".";
}
fs::path BinaryDir() {
  const char* dir = std::getenv("CASUAL3D_BINARY_DIR");
  return dir != nullptr ? dir : ".";
}
fs::path VectorsDir() { return SourceDir() / "spec" / "vectors"; }

json::Value ReadJson(const fs::path& path) {
  StatusOr<json::Value> value = json::Parse(testing::ReadTextFile(path.string()));
  EXPECT_TRUE(value.ok()) << path << ": " << value.status().ToString();
  return value.ok() ? *value : json::Value::Object();
}

// What a reader made of one package.
struct LevelSummary {
  int width = 0, height = 0;
  double present[2] = {0, 0};
  std::string graph_sha256;  // Empty if the reader does not say.
};
struct Outcome {
  bool ok = false;
  std::string message;  // The refusal.
  std::vector<LevelSummary> levels;
};

struct Vector {
  std::string name;  // Without ".c3d"; the rule's name for an invalid vector.
  fs::path path;     // Folder or .c3d file.
  bool valid = false;
};

// Every vector on disk: the valid ones listed in expected.json, then those
// under invalid/.
std::vector<Vector> AllVectors(const json::Value& expected) {
  std::vector<Vector> vectors;
  for (const auto& [name, levels] : expected.object()) {
    vectors.push_back({name, VectorsDir() / name, true});
    vectors.push_back({name, VectorsDir() / (name + ".c3d"), true});
  }
  std::set<fs::path> invalid;
  for (const auto& entry : fs::directory_iterator(VectorsDir() / "invalid"))
    invalid.insert(entry.path());
  for (const fs::path& p : invalid) vectors.push_back({p.stem().string(), p, false});
  return vectors;
}

// A reader's outcome against what the vector should give.
void Judge(const std::string& reader, const Vector& v, const json::Value& expected,
           const json::Value& refusals, const Outcome& got) {
  SCOPED_TRACE(reader + " on " + v.path.string());
  if (v.valid) {
    ASSERT_TRUE(got.ok) << "refused a valid vector: " << got.message;
    const std::vector<json::Value>& want = expected.Find(v.name)->array();
    ASSERT_EQ(got.levels.size(), want.size()) << "levels";
    for (size_t l = 0; l < want.size(); ++l) {
      const LevelSummary& s = got.levels[l];
      EXPECT_EQ(s.width, want[l].Find("width")->number_value()) << "level " << l;
      EXPECT_EQ(s.height, want[l].Find("height")->number_value()) << "level " << l;
      for (int layer = 0; layer < 2; ++layer)
        EXPECT_EQ(s.present[layer], want[l].Find("present")->array()[layer].number_value())
            << "level " << l << " layer " << layer;
      if (!s.graph_sha256.empty()) {
        EXPECT_EQ(s.graph_sha256, want[l].Find("graph_sha256")->string_value()) << "level " << l;
      }
    }
    return;
  }
  ASSERT_FALSE(got.ok) << "accepted an invalid vector (rule " << v.name << ")";
  const json::Value* words = refusals.Find(v.name);
  ASSERT_NE(words, nullptr) << "spec/vectors/refusals.json has no entry for " << v.name;
  EXPECT_NE(got.message.find(words->string_value()), std::string::npos)
      << "refused for another reason than " << v.name << ":\n  message: " << got.message
      << "\n  expected it to contain: " << words->string_value();
  // Each layer of the program says where once (it once read "level 0: level 0: ...").
  const std::regex level_prefix("level [0-9]+:");
  const auto count =
      std::distance(std::sregex_iterator(got.message.begin(), got.message.end(), level_prefix),
                    std::sregex_iterator());
  EXPECT_LE(count, 1) << "the level is named twice: " << got.message;
  // A problem of manifest.json is the manifest's, not a level's.
  if (got.message.find("manifest.json: ") != std::string::npos) {
    EXPECT_EQ(count, 0) << "a manifest problem reported as a level's: " << got.message;
  }
  // The file at fault is named (spec/package.md Sec. 9.1): a tile file,
  // manifest.json, or the .c3d container's directory.
  static const std::regex file_named(
      R"((^|[ "])(manifest\.json|single file|[A-Za-z0-9_./-]+\.webp): )");
  EXPECT_TRUE(std::regex_search(got.message, file_named))
      << "names no file of the package: " << got.message;
}

// --- The readers ------------------------------------------------------------

Outcome ReadNative(const fs::path& path) {
  Outcome out;
  encoder::WebpImageDecoder decoder;
  StatusOr<std::unique_ptr<FileSource>> source = OpenPackage(path.string());
  if (!source.ok()) {
    out.message = source.status().message();
    return out;
  }
  Manifest manifest;
  ReadOptions read;
  for (int level = 0, levels = 1; level < levels; ++level) {
    read.level = level;
    StatusOr<TwoLayerPanorama> pano = ReadPackage(**source, decoder, read, &manifest);
    if (!pano.ok()) {
      out.message = pano.status().message();
      return out;
    }
    levels = static_cast<int>(manifest.levels.size());
    LevelSummary s;
    s.width = pano->width();
    s.height = pano->height();
    for (int l = 0; l < kNumLayers; ++l)
      for (uint8_t p : pano->layer(l).present) s.present[l] += p;
    s.graph_sha256 = testing::GraphSha256Hex(*pano);
    out.levels.push_back(s);
  }
  out.ok = true;
  return out;
}

std::string Quoted(const fs::path& p) { return "'" + p.string() + "'"; }

// `casual3d validate <path>` of every vector, two at a time (the program
// takes about a quarter of a second of CPU to start).
std::vector<testing::CommandRun> RunValidate(const std::vector<Vector>& vectors) {
  // casual3d restarts itself once to ask glibc for huge pages unless the
  // environment sets that tunable (cli/main.cc); validate does not need them,
  // and the restart would load the program's shared libraries twice.
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables == nullptr || std::strstr(tunables, "glibc.malloc.hugetlb") == nullptr) {
    const std::string value = std::string(tunables != nullptr && *tunables ? tunables : "") +
                              (tunables != nullptr && *tunables ? ":" : "") +
                              "glibc.malloc.hugetlb=0";
    setenv("GLIBC_TUNABLES", value.c_str(), 1);
  }
  std::vector<testing::CommandRun> runs(vectors.size());
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t i; (i = next++) < vectors.size();)
      runs[i] = testing::Casual3d("validate " + Quoted(vectors[i].path));
  };
  std::thread other(work);
  work();
  other.join();
  return runs;
}

// What `casual3d validate` said: exit 0 with a line per level, or exit 1 with
// one line "casual3d: error: <path>: <message>".
Outcome CliOutcome(const fs::path& path, const testing::CommandRun& run) {
  Outcome out;
  out.ok = run.exit_code == 0;
  if (!out.ok) {
    const std::string prefix = "casual3d: error: " + path.string() + ": ";
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_EQ(run.output.rfind(prefix, 0), 0u)
        << "not one error line naming the package: " << run.output;
    EXPECT_EQ(run.output.find('\n'), run.output.size() - 1) << "not one line: " << run.output;
    out.message = run.output.substr(0, run.output.size() - 1);
    return out;
  }
  const std::regex line(
      R"(level ([0-9]+): ([0-9]+)x([0-9]+) ok, ([0-9]+) front and ([0-9]+) back nodes)");
  for (auto m = std::sregex_iterator(run.output.begin(), run.output.end(), line);
       m != std::sregex_iterator(); ++m) {
    EXPECT_EQ(std::stoul((*m)[1]), out.levels.size()) << run.output;
    LevelSummary s;
    s.width = std::stoi((*m)[2]);
    s.height = std::stoi((*m)[3]);
    s.present[0] = std::stod((*m)[4]);
    s.present[1] = std::stod((*m)[5]);
    out.levels.push_back(s);
  }
  return out;
}

#ifdef CASUAL3D_CONFORMANCE_WASM
// The wasm reader: one Node process reads every package
// (tests/conformance/wasm_read.mjs), one outcome per package it reported.
std::map<fs::path, Outcome> ReadWasm(const std::vector<Vector>& vectors) {
  std::string cmd = "NODE_PATH=" + Quoted(SourceDir() / "wasm-viewer" / "node_modules") + " " +
                    Quoted(CASUAL3D_NODE) + " " +
                    Quoted(SourceDir() / "tests" / "conformance" / "wasm_read.mjs") + " " +
                    Quoted(BinaryDir() / "wasm-viewer" / "dist");
  for (const Vector& v : vectors) cmd += " " + Quoted(v.path);
  std::string output;
  FILE* pipe = popen(cmd.c_str(), "r");
  char buf[4096];
  size_t n;
  while (pipe != nullptr && (n = fread(buf, 1, sizeof(buf), pipe)) > 0) output.append(buf, n);
  const int status = pipe != nullptr ? pclose(pipe) : -1;
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd << "\n" << output;
  std::map<fs::path, Outcome> outcomes;
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    StatusOr<json::Value> v = json::Parse(line);
    if (!v.ok()) {
      ADD_FAILURE() << "wasm_read.mjs printed " << line;
      continue;
    }
    Outcome out;
    out.ok = v->Find("ok")->bool_value();
    if (const json::Value* m = v->Find("message")) out.message = m->string_value();
    if (const json::Value* levels = v->Find("levels")) {
      for (const json::Value& l : levels->array()) {
        LevelSummary s;
        s.width = static_cast<int>(l.Find("width")->number_value());
        s.height = static_cast<int>(l.Find("height")->number_value());
        for (int layer = 0; layer < 2; ++layer)
          s.present[layer] = l.Find("present")->array()[layer].number_value();
        s.graph_sha256 = l.Find("graph_sha256")->string_value();
        out.levels.push_back(s);
      }
    }
    outcomes[v->Find("path")->string_value()] = out;
  }
  return outcomes;
}
#endif  // CASUAL3D_CONFORMANCE_WASM

// --- The tests ---------------------------------------------------------------

class ConformanceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(VectorsDir() / "expected.json")) GTEST_SKIP() << "no " << VectorsDir();
    expected_ = ReadJson(VectorsDir() / "expected.json");
    refusals_ = ReadJson(VectorsDir() / "refusals.json");
    vectors_ = AllVectors(expected_);
  }
  json::Value expected_ = json::Value::Object(), refusals_ = json::Value::Object();
  std::vector<Vector> vectors_;
};

// The spec's table, the invalid vectors, refusals.json and the reader checks
// name the same rules; every row that says how it is tested points at
// something that exists.
TEST_F(ConformanceTest, SpecTableVectorsAndRefusalsAgree) {
  const std::vector<testing::ConformanceRow> rows = testing::ParseConformanceTable(
      testing::ReadTextFile((SourceDir() / "spec" / "package.md").string()),
      "### 9.1 Reader conformance");
  ASSERT_GE(rows.size(), static_cast<size_t>(kNumReaderChecks))
      << "spec/package.md Sec. 9.1 table not found";
  std::set<std::string> on_disk;
  for (const Vector& v : vectors_)
    if (!v.valid) on_disk.insert(v.name);
  std::set<std::string> in_table;
  for (const testing::ConformanceRow& row : rows) {
    SCOPED_TRACE("spec/package.md Sec. 9.1: " + row.rule);
    if (row.reader == "MUST refuse") {
      EXPECT_TRUE(!row.vector.empty() || row.tested.rfind("unit tests (", 0) == 0)
          << "a MUST-refuse row names neither an invalid vector nor unit tests: " << row.tested;
    }
    if (!row.vector.empty()) {
      EXPECT_EQ(row.reader, "MUST refuse")
          << "an invalid vector for a rule readers need not refuse";
      EXPECT_TRUE(in_table.insert(row.vector).second) << row.vector << " names two rows";
      const fs::path base = VectorsDir() / "invalid" / row.vector;
      EXPECT_TRUE(fs::is_regular_file(base.string() + ".c3d")) << base << ".c3d is missing";
      // A folder unless the rule is about the .c3d container itself.
      const bool container_rule = row.rule.rfind("`.c3d`", 0) == 0;
      EXPECT_EQ(fs::exists(base / "manifest.json"), !container_rule)
          << base
          << (container_rule ? " exists for a container rule" : " (the folder form) is missing");
      ReaderCheck check;
      EXPECT_TRUE(ReaderCheckFromName(row.vector, &check))
          << row.vector << " is no check of format/reader_checks.h";
    }
    for (const std::string& q : row.quoted) {
      if (q.find('/') != std::string::npos)
        EXPECT_TRUE(fs::exists(SourceDir() / q))
            << "the table cites " << q << ", which does not exist";
      else
        EXPECT_EQ(on_disk.count(q), 1u)
            << "the table cites the vector " << q << ", which does not exist";
    }
  }
  for (const std::string& name : on_disk)
    EXPECT_EQ(in_table.count(name), 1u)
        << "invalid/" << name << " is in no row of spec/package.md Sec. 9.1";
  EXPECT_EQ(in_table.size(), static_cast<size_t>(kNumReaderChecks));
  std::set<std::string> listed;
  for (const auto& [name, words] : refusals_.object()) {
    listed.insert(name);
    EXPECT_EQ(in_table.count(name), 1u)
        << "spec/vectors/refusals.json lists " << name << ", no rule of the table";
    EXPECT_FALSE(words.string_value().empty()) << name;
  }
  for (const std::string& name : in_table)
    EXPECT_EQ(listed.count(name), 1u) << "spec/vectors/refusals.json lacks " << name;
  // Every valid vector on disk is one that expected.json describes.
  for (const auto& entry : fs::directory_iterator(VectorsDir())) {
    const std::string file = entry.path().filename().string();
    if (file == "invalid" || entry.path().extension() == ".json") continue;
    EXPECT_NE(expected_.Find(entry.path().stem().string()), nullptr)
        << entry.path() << " is not in expected.json";
  }
}

TEST_F(ConformanceTest, NativeReader) {
  for (const Vector& v : vectors_)
    Judge("native reader", v, expected_, refusals_, ReadNative(v.path));
}

TEST_F(ConformanceTest, Casual3dValidate) {
#ifndef CASUAL3D_CONFORMANCE_CLI
  GTEST_SKIP() << "casual3d is not built here (CASUAL3D_BUILD_RECONSTRUCT=OFF)";
#endif
  const std::vector<testing::CommandRun> runs = RunValidate(vectors_);
  for (size_t i = 0; i < vectors_.size(); ++i) {
    SCOPED_TRACE(vectors_[i].path.string());
    Judge("casual3d validate", vectors_[i], expected_, refusals_,
          CliOutcome(vectors_[i].path, runs[i]));
  }
}

TEST_F(ConformanceTest, WasmReaderInNode) {
#ifndef CASUAL3D_CONFORMANCE_WASM
  GTEST_SKIP() << "the wasm module or Node is not available in this build";
#else
  ASSERT_TRUE(fs::exists(BinaryDir() / "wasm-viewer" / "dist" / "format-node.js"))
      << "build the wasm_viewer target";
  ASSERT_TRUE(fs::exists(SourceDir() / "wasm-viewer" / "node_modules" / "@jsquash" / "webp"))
      << "the viewer's npm packages are missing: run npm ci in wasm-viewer (scripts/setup.sh does)";
  const std::map<fs::path, Outcome> outcomes = ReadWasm(vectors_);
  for (const Vector& v : vectors_) {
    const auto it = outcomes.find(v.path);
    if (it == outcomes.end()) {
      ADD_FAILURE() << "the wasm reader reported nothing for " << v.path;
      continue;
    }
    Judge("wasm reader", v, expected_, refusals_, it->second);
  }
#endif
}

}  // namespace
}  // namespace casual3d
