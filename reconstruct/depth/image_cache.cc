#include "reconstruct/depth/image_cache.h"

#include <chrono>
#include <stdexcept>
#include <utility>

namespace casual3d::depth {

ImageCache::ImageCache(int capacity, Loader load) : capacity_(capacity), load_(std::move(load)) {
  if (capacity < 1) throw std::invalid_argument("ImageCache: capacity must be at least 1");
}

std::shared_ptr<const ImageF> ImageCache::Get(int key) {
  std::promise<std::shared_ptr<const ImageF>> promise;
  Future future;
  bool load = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = entries_.find(key);
    if (it != entries_.end()) {
      it->second.last_used = ++clock_;
      future = it->second.image;
    } else {
      future = promise.get_future().share();
      entries_[key] = {future, ++clock_};
      ++loads_;
      load = true;
    }
    // Room is made before the load, so that its image's memory is not
    // needed on top of the one it replaces.
    TrimLocked();
  }
  if (load) {
    try {
      promise.set_value(load_(key));
    } catch (...) {
      // Forgotten before the waiters learn of it, so that TrimLocked never
      // meets a failed entry and the next Get loads again.
      {
        std::lock_guard<std::mutex> lock(mutex_);
        entries_.erase(key);
      }
      promise.set_exception(std::current_exception());
    }
  }
  return future.get();
}

void ImageCache::TrimLocked() {
  while (static_cast<int>(entries_.size()) > capacity_) {
    auto victim = entries_.end();
    for (auto it = entries_.begin(); it != entries_.end(); ++it) {
      const Future& f = it->second.image;
      // Loading (not ready) or held by a caller: stays. An image without an
      // owner (one the loader lends, use_count 0) can always go.
      if (f.wait_for(std::chrono::seconds(0)) != std::future_status::ready || f.get().use_count() > 1) continue;
      if (victim == entries_.end() || it->second.last_used < victim->second.last_used) victim = it;
    }
    if (victim == entries_.end()) return;
    entries_.erase(victim);
  }
}

int64_t ImageCache::loads() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return loads_;
}

int ImageCache::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(entries_.size());
}

}  // namespace casual3d::depth
