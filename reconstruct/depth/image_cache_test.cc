#include "reconstruct/depth/image_cache.h"

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace casual3d::depth {
namespace {

// A 1x1 image holding `key`, counting the loads per key.
struct CountingLoader {
  std::vector<std::atomic<int>> calls = std::vector<std::atomic<int>>(16);
  ImageCache::Loader Loader() {
    return [this](int key) {
      ++calls[key];
      return std::make_shared<const ImageF>(1, 1, 1, static_cast<float>(key));
    };
  }
};

TEST(ImageCacheTest, LoadsEachImageOnceWhileItIsKept) {
  CountingLoader counter;
  ImageCache cache(3, counter.Loader());
  const auto a = cache.Get(5);
  EXPECT_EQ(a->at(0, 0), 5.0f);
  EXPECT_EQ(cache.Get(5).get(), a.get());
  EXPECT_EQ(counter.calls[5], 1);
  EXPECT_EQ(cache.loads(), 1);
}

TEST(ImageCacheTest, DropsTheLeastRecentlyUsedBeyondItsCapacity) {
  CountingLoader counter;
  ImageCache cache(2, counter.Loader());
  cache.Get(0);
  cache.Get(1);
  cache.Get(0);  // 1 is now the least recently used.
  cache.Get(2);
  EXPECT_EQ(cache.size(), 2);
  cache.Get(0);
  EXPECT_EQ(counter.calls[0], 1);
  cache.Get(1);
  EXPECT_EQ(counter.calls[1], 2);  // Dropped, read again.
  EXPECT_EQ(cache.loads(), 4);
}

TEST(ImageCacheTest, NeverDropsAnImageInUse) {
  CountingLoader counter;
  ImageCache cache(1, counter.Loader());
  const auto held0 = cache.Get(0);
  const auto held1 = cache.Get(1);
  const auto held2 = cache.Get(2);
  EXPECT_EQ(cache.size(), 3);  // Over capacity while all three are held ...
  EXPECT_EQ(cache.Get(0).get(), held0.get());
  EXPECT_EQ(counter.calls[0], 1);  // ... and a held image is shared, not read again.
}

TEST(ImageCacheTest, LentImagesCanAlwaysGo) {
  ImageF stored(1, 1, 1, 7.0f);
  int calls = 0;
  ImageCache cache(1, [&](int) {
    ++calls;
    return std::shared_ptr<const ImageF>(std::shared_ptr<const ImageF>(), &stored);
  });
  const auto a = cache.Get(0);
  const auto b = cache.Get(1);
  EXPECT_EQ(cache.size(), 1);  // Owning nothing, they take no memory to keep.
  EXPECT_EQ(a.get(), &stored);
  EXPECT_EQ(b->at(0, 0), 7.0f);
}

TEST(ImageCacheTest, AFailedLoadIsNotKept) {
  int calls = 0;
  ImageCache cache(4, [&](int key) {
    if (++calls == 1) throw std::runtime_error("photo 3: unreadable");
    return std::make_shared<const ImageF>(1, 1, 1, static_cast<float>(key));
  });
  EXPECT_THROW(cache.Get(3), std::runtime_error);
  EXPECT_EQ(cache.size(), 0);
  EXPECT_EQ(cache.Get(3)->at(0, 0), 3.0f);
  EXPECT_EQ(calls, 2);
}

TEST(ImageCacheTest, ThreadsAskingForOneImageLoadItOnce) {
  std::atomic<int> calls{0};
  ImageCache cache(2, [&](int key) {
    ++calls;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    return std::make_shared<const ImageF>(1, 1, 1, static_cast<float>(key));
  });
  std::vector<const ImageF*> got(8);
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t) threads.emplace_back([&, t] { got[t] = cache.Get(4).get(); });
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(calls, 1);
  for (const ImageF* p : got) EXPECT_EQ(p, got[0]);
}

TEST(ImageCacheTest, RefusesAnEmptyCapacity) {
  EXPECT_THROW(ImageCache(0, [](int) { return std::make_shared<const ImageF>(); }), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth
