// The sparse stage's options describe every field once (sparse_stage.h,
// reconstruct/util/options_fields.h): the pipeline's cache key changes with
// any of them.

#include <gtest/gtest.h>

#include "reconstruct/sfm/sparse_stage.h"
#include "reconstruct/util/options_fields_testing.h"

namespace casual3d::sfm {
namespace {

TEST(SparseStageOptions, EveryFieldIsDescribed) {
  util::testing::ExpectEveryFieldDescribed<SparseStageOptions>("SparseStageOptions");
}

TEST(SparseStageOptions, ChangingAnyFieldChangesTheKey) {
  util::testing::ExpectEveryFieldKeyed(SparseStageOptions());
}

}  // namespace
}  // namespace casual3d::sfm
