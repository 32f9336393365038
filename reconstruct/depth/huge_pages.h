#pragma once

// Large per-photo buffers (cost volumes, MRF unaries and messages: 50-400 MB
// each) backed by transparent huge pages where the kernel offers them only on
// request (/sys/kernel/mm/transparent_hugepage/enabled = madvise, Debian's
// default). A fresh allocation is zero-filled by the kernel on first touch,
// and doing that through 4 KiB page faults took about 30% of the dense
// stage's CPU time on a virtual machine (docs/DECISIONS.md, "Dense: huge
// pages and reused buffers"); 2 MiB pages need 512
// times fewer faults. This holds for any caller of the library; the casual3d
// program also sets glibc's malloc.hugetlb tunable (cli/main.cc), which
// covers the smaller buffers too. Elsewhere (or when the kernel refuses)
// these are plain resizes.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace casual3d::depth {

// Asks for huge pages over [data, data + bytes) (whole 4 KiB pages inside).
inline void AdviseHugePages(void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kPage = 4096;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kPage - 1) & ~(kPage - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kPage - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);  // Advice only.
#else
  (void)data;
  (void)bytes;
#endif
}

// `*v` becomes n copies of `value` in a fresh allocation advised as above
// before its pages are first touched. Small sizes are a plain assign.
template <class T>
void AssignHuge(std::vector<T>* v, size_t n, const T& value = T()) {
  constexpr size_t kMinBytes = size_t{8} << 20;
  if (n * sizeof(T) < kMinBytes) {
    v->assign(n, value);
    return;
  }
  std::vector<T>().swap(*v);
  v->reserve(n);
  AdviseHugePages(v->data(), n * sizeof(T));
  v->assign(n, value);
}

// Large float buffers handed back and forth between photos. Zero-filling
// fresh pages is the kernel's work on every first touch (even with huge
// pages: about a tenth of the dense stage's CPU time, 1.1 GB per photo);
// a buffer that a finished photo gives back is taken by the next one with
// its pages already in place. Holds at most `max_buffers` (the largest
// kept); frees them on destruction. Thread-safe.
class BufferPool {
 public:
  explicit BufferPool(size_t max_buffers) : max_buffers_(max_buffers) {}
  BufferPool(const BufferPool&) = delete;
  BufferPool& operator=(const BufferPool&) = delete;

  // `*v` becomes n copies of `value`, in the smallest kept buffer that holds
  // n floats, otherwise in a fresh allocation (AssignHuge).
  void Take(std::vector<float>* v, size_t n, float value = 0.0f) {
    TakeKept(v, n);
    if (v->capacity() >= n) {
      v->assign(n, value);
    } else {
      AssignHuge(v, n, value);
    }
  }

  // `*v` becomes n floats for the caller to overwrite: a kept buffer keeps
  // its old contents (only a part beyond its old size is zeroed), a fresh
  // one is zero. Saves the fill of a buffer that is written in full anyway.
  void TakeForOverwrite(std::vector<float>* v, size_t n) {
    TakeKept(v, n);
    if (v->capacity() >= n) {
      v->resize(n);
    } else {
      AssignHuge(v, n);
    }
  }

  // Keeps `*v`'s allocation for a later Take (when it is large: 8 MiB or
  // more); `*v` is left empty.
  void Give(std::vector<float>* v) {
    std::vector<float> b;
    b.swap(*v);
    if (b.capacity() * sizeof(float) < (size_t{8} << 20) || max_buffers_ == 0) return;
    std::lock_guard<std::mutex> lock(mutex_);
    buffers_.push_back(std::move(b));
    if (buffers_.size() > max_buffers_) {
      auto smallest = std::min_element(buffers_.begin(), buffers_.end(), [](const auto& a, const auto& c) {
        return a.capacity() < c.capacity();
      });
      buffers_.erase(smallest);
    }
  }

 private:
  // Moves the smallest kept buffer that holds n floats into `*v`, if any.
  void TakeKept(std::vector<float>* v, size_t n) {
    std::lock_guard<std::mutex> lock(mutex_);
    size_t best = buffers_.size();
    for (size_t i = 0; i < buffers_.size(); ++i)
      if (buffers_[i].capacity() >= n &&
          (best == buffers_.size() || buffers_[i].capacity() < buffers_[best].capacity()))
        best = i;
    if (best < buffers_.size()) {
      v->swap(buffers_[best]);
      buffers_.erase(buffers_.begin() + static_cast<std::ptrdiff_t>(best));
    }
  }

  std::mutex mutex_;
  size_t max_buffers_;
  std::vector<std::vector<float>> buffers_;
};

// `*v` becomes n zeros, from `pool` when there is one (BufferPool::Take),
// otherwise in a fresh allocation (AssignHuge).
inline void TakeBuffer(BufferPool* pool, std::vector<float>* v, size_t n) {
  if (pool) {
    pool->Take(v, n);
  } else {
    AssignHuge(v, n);
  }
}

// `*v` becomes n floats for the caller to overwrite, from `pool` when there
// is one (BufferPool::TakeForOverwrite: a kept buffer is not zeroed again),
// otherwise a fresh allocation of zeros (AssignHuge).
inline void TakeBufferForOverwrite(BufferPool* pool, std::vector<float>* v, size_t n) {
  if (pool) {
    pool->TakeForOverwrite(v, n);
  } else {
    AssignHuge(v, n);
  }
}

}  // namespace casual3d::depth
