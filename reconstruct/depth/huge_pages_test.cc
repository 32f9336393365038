#include "reconstruct/depth/huge_pages.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace casual3d::depth {
namespace {

constexpr size_t kBig = size_t{4} << 20;  // 16 MiB of floats: kept by the pool.

TEST(AssignHuge, FillsSmallAndLargeBuffers) {
  std::vector<float> small, large;
  AssignHuge(&small, 10, 2.5f);
  AssignHuge(&large, kBig, -1.0f);
  EXPECT_EQ(small, std::vector<float>(10, 2.5f));
  ASSERT_EQ(large.size(), kBig);
  EXPECT_TRUE(std::all_of(large.begin(), large.end(), [](float v) { return v == -1.0f; }));
}

TEST(BufferPool, HandsAGivenBufferToTheNextTake) {
  BufferPool pool(2);
  std::vector<float> a;
  pool.Take(&a, kBig, 1.0f);
  a[123] = 7.0f;
  const float* storage = a.data();
  pool.Give(&a);
  EXPECT_TRUE(a.empty());
  std::vector<float> b;
  pool.Take(&b, kBig - 100, 3.0f);  // Smaller: fits in the kept buffer.
  EXPECT_EQ(b.data(), storage);
  ASSERT_EQ(b.size(), kBig - 100);
  EXPECT_TRUE(std::all_of(b.begin(), b.end(), [](float v) { return v == 3.0f; }));
  // Larger than anything kept: a fresh allocation.
  std::vector<float> c;
  pool.Take(&c, kBig + 100, 0.0f);
  EXPECT_NE(c.data(), storage);
  EXPECT_EQ(c.size(), kBig + 100);
}

TEST(BufferPool, TakesTheSmallestBufferThatFits) {
  BufferPool pool(4);
  std::vector<float> small, large;
  pool.Take(&small, kBig);
  pool.Take(&large, 2 * kBig);
  const float* small_storage = small.data();
  const float* large_storage = large.data();
  pool.Give(&large);
  pool.Give(&small);
  std::vector<float> a, b;
  pool.Take(&a, kBig);
  pool.Take(&b, kBig);
  EXPECT_EQ(a.data(), small_storage);
  EXPECT_EQ(b.data(), large_storage);
}

TEST(BufferPool, KeepsAtMostItsLimitAndNoSmallBuffers) {
  BufferPool pool(1);
  std::vector<float> a, b, tiny(100);
  pool.Take(&a, kBig);
  pool.Take(&b, 2 * kBig);
  const float* b_storage = b.data();
  pool.Give(&tiny);  // Too small to keep.
  pool.Give(&a);
  pool.Give(&b);  // Over the limit: the smaller one (a's) goes.
  std::vector<float> c, d;
  pool.Take(&c, kBig);
  EXPECT_EQ(c.data(), b_storage);
  pool.Take(&d, 10);  // Nothing left: a small fresh buffer.
  EXPECT_EQ(d.size(), 10u);
}

TEST(BufferPool, TakeForOverwriteReusesWithoutFilling) {
  BufferPool pool(2);
  std::vector<float> a;
  pool.Take(&a, kBig, 5.0f);
  const float* storage = a.data();
  pool.Give(&a);
  std::vector<float> b;
  pool.TakeForOverwrite(&b, kBig - 10);  // Fits: the kept storage, old contents.
  EXPECT_EQ(b.data(), storage);
  ASSERT_EQ(b.size(), kBig - 10);
  EXPECT_EQ(b[0], 5.0f);
  EXPECT_EQ(b[kBig - 11], 5.0f);
  pool.Give(&b);
  std::vector<float> c;
  pool.TakeForOverwrite(&c, kBig);  // Past the old size, within capacity: the tail is zero.
  EXPECT_EQ(c.data(), storage);
  ASSERT_EQ(c.size(), kBig);
  EXPECT_EQ(c[kBig - 11], 5.0f);
  EXPECT_EQ(c[kBig - 1], 0.0f);
  std::vector<float> d;
  pool.TakeForOverwrite(&d, 100);  // Nothing kept: a fresh, zeroed buffer.
  EXPECT_EQ(d, std::vector<float>(100, 0.0f));
}

}  // namespace
}  // namespace casual3d::depth
