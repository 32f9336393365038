#pragma once

// A fresh folder for one test's files, for the unit tests of base/, encoder/
// and reconstruct/: <system temp>/casual3d_<prefix>_<pid>_<test name>,
// emptied when made and removed with the object. Header only; needs
// GoogleTest (it names the folder after the running test).

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace casual3d::testing {

class ScratchDir {
 public:
  explicit ScratchDir(const std::string& prefix) {
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("casual3d_" + prefix + "_" + std::to_string(::getpid()) + "_" +
             (test != nullptr ? test->name() : "none"));
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

}  // namespace casual3d::testing
