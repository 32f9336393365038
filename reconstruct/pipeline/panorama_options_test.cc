// The panorama stage's options describe every field once (panorama_stage.h,
// reconstruct/util/options_fields.h): the pipeline's cache key changes with
// any of them.

#include <gtest/gtest.h>

#include "reconstruct/pipeline/panorama_stage.h"
#include "reconstruct/util/options_fields_testing.h"

namespace casual3d::pipeline {
namespace {

TEST(PanoramaStageOptions, EveryFieldIsDescribed) {
  util::testing::ExpectEveryFieldDescribed<PanoramaStageOptions>("PanoramaStageOptions");
}

TEST(PanoramaStageOptions, ChangingAnyFieldChangesTheKey) {
  util::testing::ExpectEveryFieldKeyed(PanoramaStageOptions());
  PanoramaStageOptions o;
  o.pano_width = 1024;  // A fixed width: every field stays checkable.
  util::testing::ExpectEveryFieldKeyed(o);
}

TEST(PanoramaStageOptions, ChecksNameTheField) {
  PanoramaStageOptions o;
  o.pano_width = 1023;
  EXPECT_EQ(o.Check().message(), "pano_width must be even");
  o = PanoramaStageOptions();
  o.pano_width = 256;
  o.stitch.solve_width = 512;
  EXPECT_EQ(o.Check().message(), "stitch.solve_width must not exceed pano_width");
}

}  // namespace
}  // namespace casual3d::pipeline
