#pragma once

// Large per-photo buffers (cost volumes, MRF unaries and messages: 50-400 MB
// each) backed by transparent huge pages where the kernel offers them only on
// request (/sys/kernel/mm/transparent_hugepage/enabled = madvise, Debian's
// default). Every photo allocates these afresh, and zero-filling them through
// 4 KiB page faults took about 30% of the dense stage's CPU time on a virtual
// machine (docs/PERFORMANCE.md, "Textureless regions, full-resolution
// refinement, huge pages"); 2 MiB pages need 512 times fewer faults. This
// holds for any caller of the library; the casual3d program also sets
// glibc's malloc.hugetlb tunable (cli/main.cc), which covers the smaller
// buffers too. Elsewhere (or when the kernel refuses) these are plain resizes.

#include <cstddef>
#include <cstdint>
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

}  // namespace casual3d::depth
