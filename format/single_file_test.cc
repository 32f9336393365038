#include "format/single_file.h"

#include <gtest/gtest.h>

#include "format/file_source.h"

namespace casual3d {
namespace {

std::vector<uint8_t> Bytes(const std::string& s) { return {s.begin(), s.end()}; }

TEST(SingleFileTest, BuildAndReadBack) {
  StatusOr<std::vector<uint8_t>> c = BuildSingleFile(
      {{"manifest.json", Bytes("{}")}, {"l0/0-0.color.webp", Bytes("abc")}, {"empty", {}}});
  ASSERT_TRUE(c.ok()) << c.status().ToString();
  // 16-byte header + 3 directory entries + 5 data bytes.
  EXPECT_EQ(c->size(), 16u + (2 + 13 + 16) + (2 + 17 + 16) + (2 + 5 + 16) + 5);
  EXPECT_EQ((*c)[0], 0x89);
  StatusOr<std::unique_ptr<SingleFileSource>> s = SingleFileSource::Create(*c);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(*(*s)->Read("l0/0-0.color.webp", 100), Bytes("abc"));
  EXPECT_EQ(*(*s)->Read("manifest.json", 100), Bytes("{}"));
  EXPECT_TRUE((*s)->Read("empty", 0)->empty());
  EXPECT_EQ((*s)->Read("l0/0-0.color.webp", 2).status().code(), StatusCode::kLimitExceeded);
  EXPECT_EQ((*s)->Read("nope", 100).status().code(), StatusCode::kNotFound);
  EXPECT_EQ((*s)->Read("../x", 100).status().code(), StatusCode::kInvalidArgument);
}

TEST(SingleFileTest, RefusesHostileContainers) {
  std::vector<uint8_t> good =
      *BuildSingleFile({{"manifest.json", Bytes("{}")}, {"a.webp", Bytes("xyz")}});
  // Every truncation fails cleanly.
  for (size_t n = 0; n < good.size() - 5; ++n)
    EXPECT_FALSE(ParseSingleFileDirectory(good.data(), n).ok()) << n;
  auto with = [&](size_t at, uint8_t v) {
    std::vector<uint8_t> b = good;
    b[at] = v;
    return ParseSingleFileDirectory(b.data(), b.size()).status();
  };
  EXPECT_EQ(with(1, 'X').code(), StatusCode::kInvalidData);             // Magic.
  EXPECT_EQ(with(8, 2).code(), StatusCode::kUnsupportedVersion);       // Major 2.
  EXPECT_TRUE(with(10, 7).ok());                                        // Minor 7 is fine.
  EXPECT_EQ(with(15, 0x7f).code(), StatusCode::kLimitExceeded);         // Entry count.
  EXPECT_EQ(with(16 + 2 + 13 + 7, 0x10).code(), StatusCode::kInvalidData);  // Offset too far.
  EXPECT_EQ(with(16 + 2 + 13 + 15, 0xff).code(), StatusCode::kInvalidData);  // Size too big.
  EXPECT_EQ(with(16 + 2, '.').code(), StatusCode::kInvalidData);        // ".anifest.json" first.
  EXPECT_EQ(BuildSingleFile({{"a", {}}}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(BuildSingleFile({{"manifest.json", {}}, {"/etc/passwd", {}}}).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(BuildSingleFile({{"manifest.json", {}}, {"a", {}}, {"a", {}}}).status().code(),
            StatusCode::kInvalidArgument);
}

// spec/package.md Sec. 8: entries may share one data range, entries the
// manifest does not list are kept (package readers ignore them), and any
// minor version of the container's major 1 is read.
TEST(SingleFileTest, SharedRangesAndUnlistedEntries) {
  std::vector<uint8_t> c =
      *BuildSingleFile({{"manifest.json", Bytes("{}")}, {"a", Bytes("xyz")}, {"b", Bytes("uvw")}});
  // Point b's data range at a's: 16 + (2 + 13 + 16) + (2 + 1 + 16) + 2 + 1.
  const size_t a_offset = 16 + 31 + 2 + 1, b_offset = 16 + 31 + 19 + 2 + 1;
  std::copy_n(c.begin() + a_offset, 8, c.begin() + b_offset);
  c[10] = 3;  // Container 1.3.
  StatusOr<std::unique_ptr<SingleFileSource>> s = SingleFileSource::Create(c);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(*(*s)->Read("b", 10), Bytes("xyz"));
  EXPECT_EQ(*(*s)->Read("a", 10), Bytes("xyz"));
}

// Each container check switched off keeps what it would refuse; reads stay
// inside the container.
TEST(SingleFileTest, ContainerChecksSwitchedOff) {
  std::vector<uint8_t> c = *BuildSingleFile(
      {{"manifest.json", Bytes("{}")}, {"a", Bytes("first")}, {"b", Bytes("other")}});
  std::vector<uint8_t> dup = c;
  dup[16 + 31 + 19 + 2] = 'a';  // Second entry "b" -> "a".
  EXPECT_NE(ParseSingleFileDirectory(dup.data(), dup.size()).status().message().find(
                "duplicate path \"a\""),
            std::string::npos);
  StatusOr<std::unique_ptr<SingleFileSource>> s =
      SingleFileSource::Create(dup, ReaderChecks::AllBut(ReaderCheck::kDuplicateEntry));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(*(*s)->Read("a", 10), Bytes("first"));  // The first of the two.
  std::vector<uint8_t> outside = c;
  outside[16 + 31 + 2 + 1 + 8] = 0xff;  // Entry a's size.
  EXPECT_FALSE(ParseSingleFileDirectory(outside.data(), outside.size()).ok());
  s = SingleFileSource::Create(outside, ReaderChecks::AllBut(ReaderCheck::kEntryOutsideFile));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ((*s)->Read("a", 1000).status().code(), StatusCode::kInvalidData);
  EXPECT_EQ(*(*s)->Read("b", 10), Bytes("other"));
}

}  // namespace
}  // namespace casual3d
