#pragma once

// Files for the unit tests of base/, encoder/, reconstruct/ and cli/: a fresh
// folder per test, emptied when made and removed with the object, a fixture
// that holds one, and whole-file reads and writes. Header only; needs
// GoogleTest (the folder is named after the running test).

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace casual3d::testing {

class ScratchDir {
 public:
  // <system temp>/casual3d_<test suite>_<test>_<pid>.
  ScratchDir() {
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    const std::string name = test != nullptr
                                 ? std::string(test->test_suite_name()) + "_" + test->name()
                                 : std::string("no_test");
    path_ = std::filesystem::temp_directory_path() /
            ("casual3d_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // path() / name, as a string.
  std::string Path(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// A fixture whose tests each get a ScratchDir.
class TestWithScratchDir : public ::testing::Test {
 protected:
  ScratchDir scratch_;
  const std::filesystem::path dir_ = scratch_.path();
};

// The bytes of the file at `path` ("" when it cannot be read).
inline std::string ReadWholeFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

// Replaces the file at `path` by `bytes` (plainly, not atomically).
inline void WriteWholeFile(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

}  // namespace casual3d::testing
