#include "format/status.h"

#include <gtest/gtest.h>

namespace casual3d {
namespace {

StatusOr<int> ParsePositive(int v) {
  if (v <= 0) return InvalidArgument("value " + std::to_string(v) + " is not positive");
  return v;
}

Status Twice(int v, int* out) {
  CASUAL3D_ASSIGN_OR_RETURN(int p, ParsePositive(v));
  *out = 2 * p;
  return Status::Ok();
}

TEST(StatusTest, OkAndErrorsCarryCodeAndMessage) {
  EXPECT_TRUE(Status::Ok().ok());
  Status s = InvalidData("manifest.json: missing field 'width'");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), StatusCode::kInvalidData);
  EXPECT_EQ(s.ToString(), "invalid data: manifest.json: missing field 'width'");
}

TEST(StatusTest, AssignOrReturnPropagates) {
  int out = 0;
  EXPECT_TRUE(Twice(4, &out).ok());
  EXPECT_EQ(out, 8);
  Status s = Twice(-1, &out);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(s.message(), "value -1 is not positive");
}

}  // namespace
}  // namespace casual3d
