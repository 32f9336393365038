// Runs every file of a fuzz target's corpus (CASUAL3D_FUZZ_CORPUS, relative to
// the source tree) through its LLVMFuzzerTestOneInput. The targets abort on any
// broken invariant, so a regression fails (or crashes) this test.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

TEST(FuzzCorpusTest, EveryInputPasses) {
  const char* source = std::getenv("CASUAL3D_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "CASUAL3D_SOURCE_DIR is not set (run under ctest)";
  const std::filesystem::path dir = std::filesystem::path(source) / CASUAL3D_FUZZ_CORPUS;
  ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir << " is missing";
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 10u) << dir << " holds too few inputs";
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    std::ifstream in(file, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
    EXPECT_EQ(LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()),
              0);
  }
}

}  // namespace
