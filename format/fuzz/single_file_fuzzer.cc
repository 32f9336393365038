// Fuzz target (format/fuzz/CMakeLists.txt): ParseSingleFileDirectory and SingleFileSource reads on arbitrary bytes.

#include <vector>

#include "format/file_source.h"
#include "format/single_file.h"

namespace casual3d::fuzz {
namespace {

int FuzzSingleFile(const uint8_t* data, size_t size) {
  StatusOr<std::unique_ptr<SingleFileSource>> source =
      SingleFileSource::Create(std::vector<uint8_t>(data, data + size));
  if (!source.ok()) return 0;
  for (const SingleFileEntry& e : (*source)->entries()) {
    StatusOr<std::vector<uint8_t>> bytes = (*source)->Read(e.path, 1u << 20);
    (void)bytes;
  }
  return 0;
}

}  // namespace
}  // namespace casual3d::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return casual3d::fuzz::FuzzSingleFile(data, size);
}
