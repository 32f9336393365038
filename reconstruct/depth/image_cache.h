#pragma once

// A small cache of images read on demand, for pass 3 of the dense stage
// (dense_free_space.h), which reads each photo's full-resolution maps once
// per photo that checks against it: a capture of any size then needs the
// memory of the photos in flight and their neighbours, not of every photo.

#include <cstdint>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>

#include "format/image.h"

namespace casual3d::depth {

// Images by key (a photo's index), each read by `load` on its first Get and
// kept; beyond `capacity` images the least recently used is dropped. An image
// that a caller still holds (its shared_ptr) is never dropped, so threads
// checking overlapping photos share one copy; while more than `capacity` are
// held the cache holds more. Thread-safe: a key asked for by several threads
// at once is loaded once, the others wait for it. A load that throws is not
// kept: its callers get the exception and the next Get loads again.
class ImageCache {
 public:
  using Loader = std::function<std::shared_ptr<const ImageF>(int key)>;

  // `capacity` >= 1.
  ImageCache(int capacity, Loader load);

  // The image of `key`, loaded if the cache does not hold it. Throws what
  // `load` throws.
  std::shared_ptr<const ImageF> Get(int key);

  int64_t loads() const;  // Calls of `load` so far.
  int size() const;       // Images held now.

 private:
  using Future = std::shared_future<std::shared_ptr<const ImageF>>;
  struct Entry {
    Future image;
    uint64_t last_used = 0;
  };
  // Drops the least recently used images that no caller holds until at most
  // capacity_ remain (or none can go).
  void TrimLocked();

  const int capacity_;
  const Loader load_;
  mutable std::mutex mutex_;
  std::map<int, Entry> entries_;
  uint64_t clock_ = 0;
  int64_t loads_ = 0;
};

}  // namespace casual3d::depth
