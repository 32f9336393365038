#include "reconstruct/util/log.h"

#include <gtest/gtest.h>

namespace casual3d::util {
namespace {

TEST(LogTest, FormatDuration) {
  EXPECT_EQ(FormatDuration(0), "0:00");
  EXPECT_EQ(FormatDuration(65), "1:05");
  EXPECT_EQ(FormatDuration(3723), "1:02:03");
  EXPECT_EQ(FormatDuration(-1), "?");
}

TEST(LogTest, JsonEscape) {
  EXPECT_EQ(JsonEscape("a\"b\\c\n"), "a\\\"b\\\\c\\n");
  EXPECT_EQ(JsonEscape(std::string("\x01", 1)), "\\u0001");
}

TEST(LogTest, ProgressCountsToTotalFromThreads) {
  Progress p("test", 100);
  for (int i = 0; i < 150; ++i) p.Advance();
  p.Finish();
  EXPECT_GE(p.ElapsedSeconds(), 0.0);
}

}  // namespace
}  // namespace casual3d::util
