#include "format/json.h"

#include <string>

#include <gtest/gtest.h>

namespace casual3d::json {
namespace {

TEST(JsonTest, ParsesAllTypesAndRoundTrips) {
  const std::string text =
      R"({"a": 1, "b": [true, false, null], "c": "x\"y\\u00e9\n", "d": -2.5e-3, "e": {}, "f": []})";
  StatusOr<Value> v = Parse(text);
  ASSERT_TRUE(v.ok()) << v.status().ToString();
  EXPECT_EQ(v->Find("a")->number_value(), 1.0);
  EXPECT_EQ(v->Find("b")->array().size(), 3u);
  EXPECT_TRUE(v->Find("b")->array()[2].is_null());
  EXPECT_EQ(v->Find("c")->string_value(), "x\"y\\u00e9\n");
  EXPECT_EQ(v->Find("d")->number_value(), -2.5e-3);
  EXPECT_TRUE(v->Find("e")->is_object());
  for (int indent : {0, 2}) {
    StatusOr<Value> again = Parse(Serialize(*v, indent));
    ASSERT_TRUE(again.ok());
    EXPECT_TRUE(*again == *v);
  }
}

TEST(JsonTest, UnicodeEscapesAndNumbersAreExact) {
  StatusOr<Value> v = Parse(R"(["\u00e9\ud83d\ude00", 0.1, 123456789012345, 1e300])");
  ASSERT_TRUE(v.ok()) << v.status().ToString();
  EXPECT_EQ(v->array()[0].string_value(), "\xC3\xA9\xF0\x9F\x98\x80");
  EXPECT_EQ(v->array()[1].number_value(), 0.1);
  EXPECT_EQ(Serialize(v->array()[2]), "123456789012345");
  StatusOr<Value> back = Parse(Serialize(*v));
  EXPECT_TRUE(*back == *v);
  EXPECT_EQ(Serialize(Value::Number(0.1)), "0.1");
  EXPECT_EQ(Serialize(Value::Number(1.0 / 3.0)), "0.3333333333333333");
}

struct BadCase {
  const char* text;
  const char* message;  // Substring of the error.
};

TEST(JsonTest, ErrorsNameTheByteOffset) {
  const BadCase cases[] = {
      {"", "byte 0: unexpected end of input"},
      {"{\"a\" 1}", "byte 5: expected ':'"},
      {"[1, 2", "unterminated array"},
      {"[01]", "leading zeros"},
      {"{\"a\":1,\"a\":2}", "duplicate key \"a\""},
      {"\"\\x\"", "invalid escape"},
      {"\"\\ud800\"", "unpaired high surrogate"},
      {"\"\xff\"", "invalid UTF-8"},
      {"\"\xc0\xaf\"", "invalid UTF-8"},
      {"[1] x", "byte 4: unexpected text after"},
      {"nul", "invalid literal"},
      {"1e999", "out of range"},
      {"\"a\nb\"", "control character"},
      {"[-]", "expected digits"},
  };
  for (const BadCase& c : cases) {
    StatusOr<Value> v = Parse(c.text);
    ASSERT_FALSE(v.ok()) << c.text;
    EXPECT_EQ(v.status().code(), StatusCode::kInvalidData) << c.text;
    EXPECT_NE(v.status().message().find(c.message), std::string::npos)
        << c.text << " gave " << v.status().message();
  }
}

TEST(JsonTest, LimitsAreEnforced) {
  std::string deep(100, '[');
  deep += std::string(100, ']');
  EXPECT_EQ(Parse(deep).status().code(), StatusCode::kLimitExceeded);
  ParseLimits limits;
  limits.max_bytes = 10;
  EXPECT_EQ(Parse("[1,2,3,4,5,6]", limits).status().code(), StatusCode::kLimitExceeded);
  limits = ParseLimits();
  limits.max_object_members = 2;
  EXPECT_EQ(Parse(R"({"a":1,"b":2,"c":3})", limits).status().code(), StatusCode::kLimitExceeded);
  limits = ParseLimits();
  limits.max_string_bytes = 4;
  EXPECT_EQ(Parse(R"("abcdefgh")", limits).status().code(), StatusCode::kLimitExceeded);
  // Exactly at the depth limit is fine.
  std::string ok(64, '[');
  ok += std::string(64, ']');
  EXPECT_TRUE(Parse(ok).ok());
}

}  // namespace
}  // namespace casual3d::json
