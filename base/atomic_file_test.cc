#include "base/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "base/testing/scratch_dir.h"

namespace casual3d::base {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public casual3d::testing::TestWithScratchDir {
 protected:
  // The names in the folder: a temporary file left behind shows here.
  std::string Listing() const {
    std::string names;
    for (const auto& e : fs::directory_iterator(dir_)) names += e.path().filename().string() + ";";
    return names;
  }
};

TEST_F(AtomicFileTest, WritesAndReplaces) {
  const std::string path = scratch_.Path("a.bin");
  ASSERT_TRUE(WriteFileAtomic(path, std::string("first")).ok());
  EXPECT_EQ(casual3d::testing::ReadWholeFile(path), "first");
  ASSERT_TRUE(WriteFileAtomic(path, std::vector<uint8_t>{'2', 'n', 'd'}).ok());
  EXPECT_EQ(casual3d::testing::ReadWholeFile(path), "2nd");
  ASSERT_TRUE(WriteFileAtomic(path, std::string()).ok());
  EXPECT_EQ(fs::file_size(path), 0u);
  EXPECT_EQ(Listing(), "a.bin;");
}

TEST_F(AtomicFileTest, TemporaryPathsAreBesideTheTargetAndDistinct) {
  const std::string path = scratch_.Path("x.exr");
  const std::string a = TemporaryPathFor(path), b = TemporaryPathFor(path);
  EXPECT_NE(a, b);
  EXPECT_EQ(fs::path(a).parent_path(), dir_);
  EXPECT_EQ(a.rfind(path + ".tmp-", 0), 0u) << a;
}

TEST_F(AtomicFileTest, AMissingFolderIsAnIoErrorNamingThePath) {
  const std::string path = scratch_.Path("no/such/folder/a.bin");
  const Status s = WriteFileAtomic(path, std::string("data"));
  EXPECT_EQ(s.code(), StatusCode::kIoError);
  EXPECT_EQ(s.message().rfind(path + ": cannot write (", 0), 0u) << s.message();
  EXPECT_EQ(Listing(), "");
}

TEST_F(AtomicFileTest, AFailedWriteLeavesTheTargetAndNoTemporaryFile) {
  const std::string path = scratch_.Path("a.txt");
  ASSERT_TRUE(WriteFileAtomic(path, std::string("old")).ok());
  std::string seen_tmp;
  const Status s = WriteAtomically(path, [&](const std::string& tmp) {
    seen_tmp = tmp;
    std::ofstream(tmp) << "half of the new";
    return IoError(path + ": disk full");
  });
  EXPECT_EQ(s.message(), path + ": disk full");
  EXPECT_FALSE(seen_tmp.empty());
  EXPECT_FALSE(fs::exists(seen_tmp));
  EXPECT_EQ(casual3d::testing::ReadWholeFile(path), "old");
  EXPECT_EQ(Listing(), "a.txt;");
}

TEST_F(AtomicFileTest, AnExceptionFromTheWriterIsRethrownAndCleanedUp) {
  const std::string path = scratch_.Path("a.txt");
  ASSERT_TRUE(WriteFileAtomic(path, std::string("old")).ok());
  EXPECT_THROW(WriteAtomically(path,
                               [&](const std::string& tmp) -> Status {
                                 std::ofstream(tmp) << "partial";
                                 throw std::runtime_error("encoder failed");
                               }),
               std::runtime_error);
  EXPECT_EQ(casual3d::testing::ReadWholeFile(path), "old");
  EXPECT_EQ(Listing(), "a.txt;");
}

TEST_F(AtomicFileTest, AFailedRenameLeavesTheTargetAndNoTemporaryFile) {
  // A non-empty folder where the file should go: the rename fails.
  const std::string path = scratch_.Path("taken");
  fs::create_directories(dir_ / "taken");
  std::ofstream((dir_ / "taken" / "keep.txt").string()) << "kept";
  const Status s = WriteFileAtomic(path, std::string("data"));
  EXPECT_EQ(s.code(), StatusCode::kIoError);
  EXPECT_EQ(s.message().rfind(path + ": cannot write (", 0), 0u) << s.message();
  EXPECT_TRUE(fs::is_directory(path));
  EXPECT_EQ(casual3d::testing::ReadWholeFile(scratch_.Path("taken/keep.txt")), "kept");
  EXPECT_EQ(Listing(), "taken;");
}

TEST_F(AtomicFileTest, ReplaceFolderSwapsAWholeFolder) {
  const std::string dir = scratch_.Path("out"), staged = scratch_.Path("out.staged");
  fs::create_directories(staged);
  std::ofstream(staged + "/a.txt") << "first";
  ASSERT_TRUE(ReplaceFolder(staged, dir).ok());  // No folder there yet.
  EXPECT_EQ(casual3d::testing::ReadWholeFile(dir + "/a.txt"), "first");
  fs::create_directories(staged);
  std::ofstream(staged + "/b.txt") << "second";
  ASSERT_TRUE(ReplaceFolder(staged, dir).ok());
  EXPECT_FALSE(fs::exists(dir + "/a.txt"));  // The old folder's files went with it.
  EXPECT_EQ(casual3d::testing::ReadWholeFile(dir + "/b.txt"), "second");
  EXPECT_EQ(Listing(), "out;");
}

TEST_F(AtomicFileTest, AFailedReplaceFolderPutsTheOldFolderBack) {
  const std::string dir = scratch_.Path("out");
  fs::create_directories(dir);
  std::ofstream(dir + "/a.txt") << "old";
  const Status s = ReplaceFolder(scratch_.Path("never-written"), dir);
  EXPECT_EQ(s.code(), StatusCode::kIoError);
  EXPECT_EQ(s.message().rfind(dir + ": cannot move the new folder into place (", 0), 0u)
      << s.message();
  EXPECT_EQ(casual3d::testing::ReadWholeFile(dir + "/a.txt"), "old");
  EXPECT_EQ(Listing(), "out;");
}

}  // namespace
}  // namespace casual3d::base
