// The dense stage's options describe every field once (dense_stage.h,
// reconstruct/util/options_fields.h): the pipeline's cache key changes with
// any of them. The key once listed 26 fields by hand and missed, among
// others, mrf.max_iterations and the sub-label and edge-median options.

#include <gtest/gtest.h>

#include "reconstruct/depth/dense_stage.h"
#include "reconstruct/util/options_fields_testing.h"

namespace casual3d::depth {
namespace {

TEST(DenseOptions, EveryFieldIsDescribed) {
  util::testing::ExpectEveryFieldDescribed<DenseOptions>("DenseOptions");
}

TEST(DenseOptions, ChangingAnyFieldChangesTheKey) {
  util::testing::ExpectEveryFieldKeyed(DenseOptions());
  // The fields the hand-written key missed.
  const std::string base = util::FieldsKeyText(DenseOptions());
  DenseOptions o;
  o.mrf.max_iterations = 7;
  EXPECT_NE(util::FieldsKeyText(o), base);
  o = DenseOptions();
  o.sublabel.smooth_radius = 3;
  EXPECT_NE(util::FieldsKeyText(o), base);
  o = DenseOptions();
  o.edge_median.radius = 9;
  EXPECT_NE(util::FieldsKeyText(o), base);
  // Threads do not change the output.
  o = DenseOptions();
  o.num_threads = 3;
  o.sweep.num_threads = 3;
  EXPECT_EQ(util::FieldsKeyText(o), base);
}

TEST(DenseOptions, ChecksNameTheField) {
  DenseOptions o;
  EXPECT_TRUE(o.Check().ok());
  o.mrf.max_iterations = 0;
  EXPECT_EQ(o.Check().message(), "mrf.max_iterations 0 outside [1, 1000]");
  o = DenseOptions();
  o.relabel.window_step = o.relabel.window_radius + 1;
  EXPECT_EQ(o.Check().message(), "relabel.window_step must not exceed window_radius");
  o = DenseOptions();
  o.fullres.steps = 8;
  EXPECT_EQ(o.Check().message(), "fullres.steps must be odd");
}

}  // namespace
}  // namespace casual3d::depth
