#include "reconstruct/util/union_find.h"

#include <gtest/gtest.h>

namespace casual3d::util {
namespace {

TEST(UnionFind, RootsAreTheSmallestMembers) {
  UnionFind sets(6);
  sets.Union(4, 2);
  sets.Union(5, 4);
  sets.Union(3, 1);
  EXPECT_EQ(sets.Find(5), 2);
  EXPECT_EQ(sets.Find(4), 2);
  EXPECT_EQ(sets.Find(3), 1);
  EXPECT_EQ(sets.Find(0), 0);
  sets.Union(5, 1);  // Joins {1, 3} and {2, 4, 5}.
  for (int i : {2, 3, 4, 5}) EXPECT_EQ(sets.Find(i), 1);
  EXPECT_EQ(sets.Find(0), 0);
}

}  // namespace
}  // namespace casual3d::util
