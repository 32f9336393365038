#include "reconstruct/depth/cost_cache.h"

#include <algorithm>
#include <cstdint>
#include <fstream>

#include "base/atomic_file.h"
#include "reconstruct/io/file_util.h"

namespace casual3d::depth {
namespace {

constexpr size_t kCacheChunk = size_t{1} << 20;  // Costs per chunk.

}  // namespace

void WriteCostCache(const std::string& path, const CostVolume& vol) {
  io::ThrowIfError(base::WriteAtomically(path, [&](const std::string& tmp) {
    std::ofstream f(tmp, std::ios::binary);
    std::vector<uint16_t> q(std::min(kCacheChunk, vol.cost.size()));
    for (size_t begin = 0; begin < vol.cost.size(); begin += kCacheChunk) {
      const size_t count = std::min(kCacheChunk, vol.cost.size() - begin);
      // Rounded half away from zero as std::lround, in a loop that vectorises
      // (the fraction of a float below 2^23 is exact).
      const float* c = vol.cost.data() + begin;
      for (size_t i = 0; i < count; ++i) {
        const float x = std::min(1.0f, std::max(0.0f, c[i])) * 65535.0f;
        const int t = static_cast<int>(x);
        q[i] = static_cast<uint16_t>(t + (x - static_cast<float>(t) >= 0.5f ? 1 : 0));
      }
      f.write(reinterpret_cast<const char*>(q.data()), static_cast<std::streamsize>(count * 2));
    }
    f.write(reinterpret_cast<const char*>(vol.photo_weight.data()),
            static_cast<std::streamsize>(vol.photo_weight.size() * sizeof(float)));
    f.close();
    if (!f) return IoError(path + ": cannot write the cost cache (disk full?)");
    return Status::Ok();
  }));
}

void ReadCostCache(const std::string& path, size_t total, std::vector<float>* cost, ImageF* photo_weight) {
  cost->resize(total);
  std::ifstream f(path, std::ios::binary);
  if (!f) throw io::IoException(path + ": cost cache missing; rerun the sweep of this photo");
  std::vector<uint16_t> q(std::min(kCacheChunk, total));
  for (size_t begin = 0; begin < total && f; begin += kCacheChunk) {
    const size_t count = std::min(kCacheChunk, total - begin);
    f.read(reinterpret_cast<char*>(q.data()), static_cast<std::streamsize>(count * 2));
    float* c = cost->data() + begin;
    for (size_t i = 0; i < count; ++i) c[i] = q[i] * (1.0f / 65535.0f);
  }
  if (photo_weight)
    f.read(reinterpret_cast<char*>(photo_weight->data()),
           static_cast<std::streamsize>(photo_weight->width() * photo_weight->height() * sizeof(float)));
  if (!f) throw io::IoException(path + ": cost cache truncated; rerun the sweep of this photo");
}

}  // namespace casual3d::depth
