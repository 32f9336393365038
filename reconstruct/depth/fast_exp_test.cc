#include "reconstruct/depth/fast_exp.h"

#include <gtest/gtest.h>

#include <cmath>

namespace casual3d::depth {
namespace {

TEST(ExpNonPositive, MatchesStdExpWithinItsBound) {
  double worst = 0;
  float worst_x = 0;
  for (int i = 0; i <= 1000000; ++i) {
    const float x = -87.0f * static_cast<float>(i) / 1000000.0f;
    const double want = std::exp(static_cast<double>(x));
    const double rel = std::abs(ExpNonPositive(x) - want) / want;
    if (rel > worst) {
      worst = rel;
      worst_x = x;
    }
  }
  EXPECT_LT(worst, 5e-7) << "at x = " << worst_x;
  EXPECT_EQ(ExpNonPositive(0.0f), 1.0f);
  // Points where the rounding of x / ln 2 changes (k = -1, -2).
  for (float x : {-0.3465736f, -0.3465737f, -1.0397208f, -1.0397209f})
    EXPECT_NEAR(ExpNonPositive(x), std::exp(x), 5e-7 * std::exp(x)) << x;
  // Far below the range: the value at -87, a tiny positive weight.
  EXPECT_GT(ExpNonPositive(-1000.0f), 0.0f);
  EXPECT_LT(ExpNonPositive(-1000.0f), 1e-37f);
}

}  // namespace
}  // namespace casual3d::depth
