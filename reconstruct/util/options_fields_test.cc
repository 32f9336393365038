#include "reconstruct/util/options_fields.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include "reconstruct/util/options_fields_testing.h"
#include "reconstruct/util/options_json.h"

namespace casual3d::util {
namespace {

enum class Mode { kA, kB, kC };

struct Inner {
  double search = 1.0;
  double step = 0.25;

  template <typename Self, typename V>
  static void DescribeFields(Self& o, V& v) {
    v.Field("search", o.search, Rule::OpenClosed(0, 4), "Half-width of the search, labels");
    v.Field("step", o.step, Rule::Above(0), "Step of the search, labels");
    v.Require(o.step <= o.search, "step", "must not exceed search");
  }
};

struct Outer {
  int radius = 8;
  bool enabled = true;
  Mode mode = Mode::kA;
  std::string model = "PINHOLE";
  double focal = 0.0;
  Inner inner;
  int num_threads = 0;

  template <typename Self, typename V>
  static void DescribeFields(Self& o, V& v) {
    v.Field("radius", o.radius, Rule::Closed(0, 32), "Window radius, pixels; 0 = off");
    v.Field("enabled", o.enabled, Rule::Any(), "Run the step");
    v.Field("mode", o.mode, Rule::Closed(0, 2), "Mode: 0 a, 1 b, 2 c");
    v.Field("model", o.model, Rule::OneOf({"PINHOLE", "OPENCV"}), "Camera model");
    v.Field("focal", o.focal, Rule::ZeroOr(Rule::Closed(1, 1e6)), "Focal length, pixels; 0 = none");
    v.Struct("inner", o.inner);
    v.Field("num_threads", o.num_threads, Rule::AtLeast(0), "Threads; 0 = all cores", Keyed::kNo);
  }
};

// Like Outer, with a field left out of its description.
struct Forgotten {
  int a = 0;
  int b = 0;
  template <typename Self, typename V>
  static void DescribeFields(Self& o, V& v) {
    v.Field("a", o.a, Rule::Any(), "A");
  }
};

TEST(OptionsFields, ChecksRangesAndRequirementsNamingThePath) {
  Outer o;
  EXPECT_TRUE(CheckFields(o).ok());
  o.radius = 33;
  EXPECT_EQ(CheckFields(o).message(), "radius 33 outside [0, 32]");
  o = Outer();
  o.inner.step = 2;
  EXPECT_EQ(CheckFields(o).message(), "inner.step must not exceed search");
  o = Outer();
  o.inner.search = 0;
  EXPECT_EQ(CheckFields(o).message(), "inner.search 0 outside (0, 4]");
  o = Outer();
  o.model = "RADIAL";
  EXPECT_EQ(CheckFields(o).message(), "model \"RADIAL\" outside one of PINHOLE, OPENCV");
  o = Outer();
  o.focal = 0.5;
  EXPECT_EQ(CheckFields(o).message(), "focal 0.5 outside 0 or [1, 1e+06]");
  o.focal = 2;
  EXPECT_TRUE(CheckFields(o).ok());
  o.inner.search = std::nan("");
  EXPECT_FALSE(CheckFields(o).ok());
  o = Outer();
  o.num_threads = -1;
  EXPECT_EQ(CheckFields(o).message(), "num_threads -1 outside >= 0");
}

TEST(OptionsFields, BoundsReadAsWritten) {
  EXPECT_EQ(Rule::Closed(0, 0.5).Text(), "[0, 0.5]");
  EXPECT_EQ(Rule::ZeroOr(Rule::Closed(1, 1e6)).Text(), "0 or [1, 1e+06]");
  // An integer that %g would round is written in full.
  EXPECT_EQ(Rule::Closed(0, 2147483648.0).Text(), "[0, 2147483648]");
}

TEST(OptionsFields, KeyTextListsEveryKeyedFieldExactly) {
  Outer o;
  o.inner.search = 0.1;
  EXPECT_EQ(FieldsKeyText(o),
            "radius=8\nenabled=true\nmode=0\nmodel=\"PINHOLE\"\nfocal=0\n"
            "inner.search=0.1\ninner.step=0.25\n");
  // The shortest text that reads back to the same double.
  for (const double v : {0.1, 1.0 / 3.0, 2.5e-5, 1e300, 123456789.125}) {
    EXPECT_EQ(std::strtod(FormatFieldValue(v).c_str(), nullptr), v);
  }
  EXPECT_EQ(FormatFieldValue(std::string("a\"b\\c\nd")), "\"a\\\"b\\\\c\\x0ad\"");
}

TEST(OptionsFields, EveryFieldChangesTheKey) {
  testing::ExpectEveryFieldDescribed<Outer>("Outer");
  testing::ExpectEveryFieldKeyed(Outer());
}

TEST(OptionsFields, CountsTheStructsMembers) {
  EXPECT_EQ(AggregateFieldCount<Outer>(), 7u);
  EXPECT_EQ(AggregateFieldCount<Inner>(), 2u);
  EXPECT_EQ(DescribedFieldCount<Outer>(), 7u);
  // A field left out of the description is noticed.
  EXPECT_EQ(AggregateFieldCount<Forgotten>(), 2u);
  EXPECT_EQ(DescribedFieldCount<Forgotten>(), 1u);
}

TEST(OptionsFields, FindsAFieldsDescriptionByAddress) {
  Outer o;
  const FieldInfo info = DescribeField(o, o.inner.step);
  EXPECT_TRUE(info.found);
  EXPECT_EQ(info.path, "inner.step");
  EXPECT_EQ(info.rule.Text(), "> 0");
  EXPECT_EQ(info.meaning, "Step of the search, labels");
  int elsewhere = 0;
  EXPECT_FALSE(DescribeField(o, elsewhere).found);
}

TEST(OptionsFields, ReportsEveryFieldAsJson) {
  Outer o;
  o.mode = Mode::kC;
  const nlohmann::json j = FieldsJson(o);
  EXPECT_EQ(j["radius"], 8);
  EXPECT_EQ(j["mode"], 2);
  EXPECT_EQ(j["model"], "PINHOLE");
  EXPECT_EQ(j["inner"]["step"], 0.25);
  EXPECT_EQ(j["num_threads"], 0);
  EXPECT_EQ(j.size(), 7u);
}

}  // namespace
}  // namespace casual3d::util
