#include "reconstruct/util/html.h"

#include <gtest/gtest.h>

namespace casual3d::util {
namespace {

TEST(HtmlTest, EscapesMarkupCharacters) {
  EXPECT_EQ(HtmlEscape("a<b>&\"c\"'"), "a&lt;b&gt;&amp;&quot;c&quot;'");
  EXPECT_EQ(HtmlEscape(""), "");
  EXPECT_EQ(HtmlEscape("fern/IMG_4026.JPG"), "fern/IMG_4026.JPG");
}

}  // namespace
}  // namespace casual3d::util
