// The options of `casual3d encode` and `export` describe fields of structs
// that check themselves (encoder::PackageOptions, encoder::GltfExportOptions,
// MeshSimplifyOptions): every value the description admits at the ends of a
// field's range must pass those checks too.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include "cli/encode_options.h"
#include "cli/export_options.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::cli {
namespace {

using util::Keyed;
using util::Rule;

// The path and rule of every described field.
class RulesVisitor : public util::FieldPath {
 public:
  template <typename T>
  void Field(const char* name, const T&, const Rule& rule, const char*, Keyed = Keyed::kYes) {
    rules.emplace_back(Path(name), rule);
  }
  template <typename S>
  void Struct(const char* name, S& sub) {
    Nested(name, sub, *this);
  }
  void Require(bool, const char*, const std::string&) {}
  std::vector<std::pair<std::string, Rule>> rules;
};

// Sets the field at `path` to `number` (numbers) or `text` (strings).
class SetVisitor : public util::FieldPath {
 public:
  SetVisitor(std::string path, double number, std::string text)
      : path_(std::move(path)), number_(number), text_(std::move(text)) {}
  template <typename T>
  void Field(const char* name, T& field, const Rule&, const char*, Keyed = Keyed::kYes) {
    if (Path(name) != path_) return;
    if constexpr (std::is_same_v<T, std::string>) {
      field = text_;
    } else if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      field = static_cast<T>(number_);
    }
  }
  template <typename S>
  void Struct(const char* name, S& sub) {
    Nested(name, sub, *this);
  }
  void Require(bool, const char*, const std::string&) {}

 private:
  std::string path_;
  double number_;
  std::string text_;
};

template <typename Options>
void ExpectDescribedEndsPassCheck(const Options& defaults) {
  RulesVisitor rules;
  Options::DescribeFields(defaults, rules);
  ASSERT_FALSE(rules.rules.empty());
  for (const auto& [path, rule] : rules.rules) {
    std::vector<std::pair<double, std::string>> values;
    for (const std::string& c : rule.choices()) values.push_back({0, c});
    if (rule.zero_allowed()) values.push_back({0, ""});
    if (std::isfinite(rule.lo()) && rule.Admits(rule.lo())) values.push_back({rule.lo(), ""});
    if (std::isfinite(rule.hi()) && rule.Admits(rule.hi())) values.push_back({rule.hi(), ""});
    for (const auto& [number, text] : values) {
      Options o = defaults;
      SetVisitor set(path, number, text);
      Options::DescribeFields(o, set);
      const Status st = o.Check();
      EXPECT_TRUE(st.ok()) << path << " = " << (text.empty() ? std::to_string(number) : text)
                           << ": " << st.message();
    }
  }
}

TEST(CommandOptionsTest, EncodeRangesLieInsidePackageOptionsCheck) {
  ExpectDescribedEndsPassCheck(EncodeCommandOptions());
}

TEST(CommandOptionsTest, ExportRangesLieInsideTheGltfAndSimplifyChecks) {
  ExpectDescribedEndsPassCheck(ExportOptions());
}

TEST(CommandOptionsTest, ChecksNameTheField) {
  EncodeCommandOptions encode;
  EXPECT_TRUE(encode.Check().ok());
  encode.package.tile_size = 8;
  EXPECT_EQ(encode.Check().message(), "package.tile_size 8 outside [16, 4096]");
  ExportOptions exported;
  EXPECT_TRUE(exported.Check().ok());
  exported.texture = "gif";
  EXPECT_EQ(exported.Check().message(), "texture \"gif\" outside one of jpeg, png");
}

}  // namespace
}  // namespace casual3d::cli
