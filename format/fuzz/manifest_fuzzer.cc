// Fuzz target (format/fuzz/CMakeLists.txt): json::Parse and ParseManifest on arbitrary bytes, then serialize/parse round trips.

#include <cstdlib>
#include <string_view>

#include "format/json.h"
#include "format/manifest.h"

namespace casual3d::fuzz {
namespace {

int FuzzManifest(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  StatusOr<json::Value> value = json::Parse(text);
  if (value.ok()) {
    // Serializing and parsing again must give the same value.
    StatusOr<json::Value> again = json::Parse(json::Serialize(*value));
    if (!again.ok() || !(*again == *value)) std::abort();
  }
  // The rules that only refuse (no change to what is parsed) switched off as well.
  ReaderChecks lenient;
  for (ReaderCheck c : {ReaderCheck::kUnknownMajor, ReaderCheck::kNestingTooDeep,
                        ReaderCheck::kNearEqualsFar, ReaderCheck::kPathEscape})
    lenient.Disable(c);
  (void)ParseManifest(text, lenient);
  StatusOr<Manifest> manifest = ParseManifest(text);
  if (manifest.ok()) {
    StatusOr<Manifest> again = ParseManifest(SerializeManifest(*manifest));
    if (!again.ok()) std::abort();
    for (size_t l = 0; l < manifest->levels.size(); ++l) {
      for (size_t t = 0; t < manifest->levels[l].tiles.size(); ++t) {
        int x, y, w, h;
        manifest->TileRect(static_cast<int>(l), static_cast<int>(t), &x, &y, &w, &h);
        if (w <= 0 || h <= 0 || x + w > manifest->levels[l].width) std::abort();
      }
    }
  }
  return 0;
}

}  // namespace
}  // namespace casual3d::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return casual3d::fuzz::FuzzManifest(data, size);
}
