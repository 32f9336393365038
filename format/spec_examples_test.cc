// The worked examples of the specs, recomputed from the text so that the text
// cannot go stale: the graph_sha256 bytes and digest of spec/package.md Sec. 9,
// the octahedral fold of Sec. 4.3, and which nodes the depth-ratio rule of
// spec/mesh.md Sec. 6 links when several candidates qualify.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "format/testing/graph_digest.h"
#include "format/testing/test_panoramas.h"
#include "format/tile_codec.h"
#include "format/two_layer.h"

namespace casual3d {
namespace {

std::string ReadSpec(const std::string& name) {
  const char* source = std::getenv("CASUAL3D_SOURCE_DIR");
  const std::string path = std::string(source != nullptr ? source : ".") + "/spec/" + name;
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << "cannot read " << path;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The fenced code block of `text` that contains `marker`.
std::string CodeBlockWith(const std::string& text, const std::string& marker) {
  const size_t at = text.find(marker);
  if (at == std::string::npos) return "";
  const size_t begin = text.rfind("```\n", at), end = text.find("```", at);
  if (begin == std::string::npos || end == std::string::npos) return "";
  return text.substr(begin + 4, end - begin - 4);
}

// The 2x2 level of the example, as the prose and table describe it.
TwoLayerPanorama GraphExamplePanorama() {
  TwoLayerPanorama p(2, 2);
  auto node = [&p](int layer, int x, int y, uint8_t label, uint8_t links) {
    LayerData& d = p.layer(layer);
    const size_t i = p.index(x, y);
    d.present[i] = 1;
    d.depth_m[i] = layer == kFront ? 2.0f : 3.0f;
    d.normal[3 * i + 2] = 1.0f;
    d.label[i] = label;
    d.links[i] = links;
  };
  auto links = [](std::initializer_list<std::pair<Direction, Link>> list) {
    uint8_t b = 0;
    for (const auto& [d, l] : list) b = SetLink(b, d, l);
    return b;
  };
  node(kFront, 0, 0, 0, links({{kRight, Link::kFront}, {kDown, Link::kFront}}));
  node(kFront, 1, 0, 0, links({{kLeft, Link::kFront}, {kDown, Link::kBack}}));
  node(kFront, 0, 1, 0, links({{kRight, Link::kFront}, {kUp, Link::kFront}}));
  node(kFront, 1, 1, 1, links({{kLeft, Link::kFront}}));
  node(kBack, 1, 1, 1, links({{kUp, Link::kFront}}));
  return p;
}

TEST(SpecExamplesTest, GraphSha256ExampleOfPackageSection9) {
  const std::string spec = ReadSpec("package.md");
  const std::string block = CodeBlockWith(spec, "graph_sha256 = ");
  ASSERT_FALSE(block.empty())
      << "spec/package.md Sec. 9: no code block with the graph_sha256 example";
  const TwoLayerPanorama pano = GraphExamplePanorama();
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();

  // The rows of bytes, named and in the order of Sec. 9.
  const char* kRows[] = {"front present", "front label", "front links",
                         "back present",  "back label",  "back links"};
  std::vector<uint8_t> bytes;
  std::istringstream lines(block);
  std::string line, digest;
  int row = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("graph_sha256 = ", 0) == 0) {
      digest = line.substr(15);
      continue;
    }
    ASSERT_LT(row, 6) << line;
    ASSERT_EQ(line.rfind(kRows[row], 0), 0u)
        << "expected the row \"" << kRows[row] << "\": " << line;
    std::istringstream hex(line.substr(std::string(kRows[row]).size()));
    std::string b;
    while (hex >> b) bytes.push_back(static_cast<uint8_t>(std::stoul(b, nullptr, 16)));
    ++row;
  }
  EXPECT_EQ(row, 6);
  EXPECT_EQ(bytes, testing::GraphBytes(pano));
  EXPECT_EQ(digest, testing::GraphSha256Hex(pano));

  // The table's links bytes: front then back of pixels (0, 0), (1, 0), (0, 1), (1, 1).
  const std::regex table_row(R"(\| \(([01]), ([01])\) \|([^\n]*))");
  int rows = 0;
  for (auto m = std::sregex_iterator(spec.begin(), spec.end(), table_row);
       m != std::sregex_iterator(); ++m) {
    const int x = std::stoi((*m)[1]), y = std::stoi((*m)[2]);
    const std::string cells = (*m)[3];
    const std::regex hex(R"(`0x([0-9a-f]{2})`)");
    int layer = 0;
    for (auto h = std::sregex_iterator(cells.begin(), cells.end(), hex);
         h != std::sregex_iterator(); ++h) {
      while (layer < kNumLayers && !pano.present(layer, x, y)) ++layer;
      ASSERT_LT(layer, kNumLayers) << (*m)[0];
      EXPECT_EQ(std::stoul((*h)[1], nullptr, 16), pano.layer(layer).links[pano.index(x, y)])
          << (*m)[0];
      ++layer;
    }
    ++rows;
  }
  EXPECT_EQ(rows, 4) << "the example's table of spec/package.md Sec. 9";
}

TEST(SpecExamplesTest, OctahedralFoldExampleOfPackageSection4_3) {
  const std::string spec = ReadSpec("package.md");
  EXPECT_NE(spec.find("The fold is a\nsimultaneous assignment"), std::string::npos);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      spec, m,
      std::regex(
          R"(Example \(informative\), `b = ([0-9]+)` \(`M = ([0-9]+)`\), decoding the code `\(([0-9]+), ([0-9]+)\)`)")))
      << "spec/package.md Sec. 4.3: the fold example is missing";
  NormalQuantization q;
  q.bits = std::stoi(m[1]);
  EXPECT_EQ(q.MaxCode(), std::stoi(m[2]));
  const uint8_t code[2] = {static_cast<uint8_t>(std::stoi(m[3])),
                           static_cast<uint8_t>(std::stoi(m[4]))};
  const std::string rest = m.suffix();
  const std::string number = R"((-?[0-9]+\.[0-9]+))";
  const std::string triple = "\\(" + number + ", " + number + ", " + number + "\\)";
  std::smatch right, wrong;
  ASSERT_TRUE(std::regex_search(rest, right, std::regex("normalised = " + triple)));
  ASSERT_TRUE(std::regex_search(rest, wrong, std::regex("the wrong normal " + triple)));

  float normal[3];
  ASSERT_TRUE(DecodeOctahedral(code, q, normal));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(normal[c], std::stod(right[c + 1]), 1e-6) << "axis " << c;

  // The fold done one assignment after the other, which the note warns against.
  const double step = 2.0 / (q.MaxCode() - 1);
  double u = (code[0] - 1) * step - 1, v = (code[1] - 1) * step - 1;
  const double z = 1 - std::fabs(u) - std::fabs(v);
  ASSERT_LT(z, 0) << "the example must fold";
  u = (1 - std::fabs(v)) * (u >= 0 ? 1 : -1);
  v = (1 - std::fabs(u)) * (v >= 0 ? 1 : -1);
  const double len = std::sqrt(u * u + v * v + z * z);
  const double sequential[3] = {u / len, v / len, z / len};
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(sequential[c], std::stod(wrong[c + 1]), 1e-6) << "axis " << c;
  EXPECT_GT(std::fabs(sequential[1] - normal[1]), 0.1)
      << "the example does not tell the two folds apart";
}

// A 4 x 1 panorama with nodes in columns 0 and 1 only, at the front and back
// depths given (0: no node), linked by the rule of spec/mesh.md Sec. 6.
TwoLayerPanorama PairPanorama(float front0, float back0, float front1, float back1) {
  TwoLayerPanorama p(4, 1);
  const float depths[2][2] = {{front0, back0}, {front1, back1}};
  for (int x = 0; x < 2; ++x) {
    for (int l = 0; l < kNumLayers; ++l) {
      if (depths[x][l] == 0) continue;
      LayerData& d = p.layer(l);
      d.present[x] = 1;
      d.depth_m[x] = depths[x][l];
    }
  }
  testing::LinkByDepthRatio(&p, 0.75f);
  return p;
}

Link RightLink(const TwoLayerPanorama& p, int layer) {
  return GetLink(p.layer(layer).links[0], kRight);
}

TEST(SpecExamplesTest, DepthRatioLinkPairingOfMeshSection6) {
  const std::string spec = ReadSpec("mesh.md");
  EXPECT_NE(spec.find("`LinkByDepthRatio`"), std::string::npos);
  EXPECT_NE(spec.find("a tie\ngoes to the front layer"), std::string::npos);
  // Front 4 m beside front 1 m and back 4 m: to the back node only.
  TwoLayerPanorama p = PairPanorama(4, 0, 1, 4);
  ASSERT_TRUE(p.Validate().ok()) << p.Validate().ToString();
  EXPECT_EQ(RightLink(p, kFront), Link::kBack);
  EXPECT_EQ(GetLink(p.layer(kFront).links[1], kLeft), Link::kNone);
  // Front 1 m and back 4 m on both sides: front to front, back to back.
  p = PairPanorama(1, 4, 1, 4);
  ASSERT_TRUE(p.Validate().ok()) << p.Validate().ToString();
  EXPECT_EQ(RightLink(p, kFront), Link::kFront);
  EXPECT_EQ(RightLink(p, kBack), Link::kBack);
  // Front and back at 4 m beside a front node at 4 m: the tie goes to the
  // front node, the back node stays unlinked to the right.
  p = PairPanorama(4, 4, 4, 0);
  ASSERT_TRUE(p.Validate().ok()) << p.Validate().ToString();
  EXPECT_EQ(RightLink(p, kFront), Link::kFront);
  EXPECT_EQ(RightLink(p, kBack), Link::kNone);
}

}  // namespace
}  // namespace casual3d
