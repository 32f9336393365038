// Fuzz target (format/fuzz/CMakeLists.txt): ParseSingleFileDirectory and SingleFileSource reads on arbitrary bytes,
// with every check on and with the container checks that keep entries (duplicate, outside the file) off.

#include <vector>

#include "format/file_source.h"
#include "format/single_file.h"

namespace casual3d::fuzz {
namespace {

void ReadAll(const uint8_t* data, size_t size, const ReaderChecks& checks) {
  StatusOr<std::unique_ptr<SingleFileSource>> source =
      SingleFileSource::Create(std::vector<uint8_t>(data, data + size), checks);
  if (!source.ok()) return;
  for (const SingleFileEntry& e : (*source)->entries()) {
    StatusOr<std::vector<uint8_t>> bytes = (*source)->Read(e.path, 1u << 20);
    (void)bytes;
  }
}

int FuzzSingleFile(const uint8_t* data, size_t size) {
  ReadAll(data, size, ReaderChecks());
  ReaderChecks lenient;
  lenient.Disable(ReaderCheck::kDuplicateEntry);
  lenient.Disable(ReaderCheck::kEntryOutsideFile);
  lenient.Disable(ReaderCheck::kManifestNotFirst);
  ReadAll(data, size, lenient);
  return 0;
}

}  // namespace
}  // namespace casual3d::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return casual3d::fuzz::FuzzSingleFile(data, size);
}
