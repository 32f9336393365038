#include "reconstruct/sfm/colmap_database.h"

#include <sqlite3.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace casual3d::sfm {
namespace {

// The tables of a COLMAP 3.8 database that the sparse stage reads and writes.
const char* kSchema =
    "CREATE TABLE images (image_id INTEGER PRIMARY KEY AUTOINCREMENT NOT NULL, name TEXT NOT NULL "
    "UNIQUE, camera_id INTEGER NOT NULL);"
    "CREATE TABLE descriptors (image_id INTEGER PRIMARY KEY NOT NULL, rows INTEGER NOT NULL, cols "
    "INTEGER NOT NULL, data BLOB);"
    "CREATE TABLE matches (pair_id INTEGER PRIMARY KEY NOT NULL, rows INTEGER NOT NULL, cols "
    "INTEGER NOT NULL, data BLOB);";

class ColmapDatabaseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char dir[] = "/tmp/casual3d_db_test_XXXXXX";
    ASSERT_NE(::mkdtemp(dir), nullptr);
    dir_ = dir;
    path_ = dir_ + "/database.db";
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, kSchema, nullptr, nullptr, nullptr), SQLITE_OK);
    // Ids out of name order, one image without descriptors, one with spaces.
    AddImage(db, 5, "b photo.jpg", 2, 3);
    AddImage(db, 2, "c.jpg", 3, 0);
    AddImage(db, 9, "a.jpg", 1, 7);
    sqlite3_exec(db, "INSERT INTO images (image_id, name, camera_id) VALUES (4, 'd.jpg', 1)",
                 nullptr, nullptr, nullptr);
    sqlite3_close(db);
  }
  void TearDown() override {
    std::remove(path_.c_str());
    ::rmdir(dir_.c_str());
  }
  static void AddImage(sqlite3* db, int id, const std::string& name, int rows, int fill) {
    const std::string sql = "INSERT INTO images (image_id, name, camera_id) VALUES (" +
                            std::to_string(id) + ", '" + name + "', 1)";
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(db, "INSERT INTO descriptors VALUES (?, ?, 128, ?)", -1, &s, nullptr);
    std::vector<uint8_t> data(static_cast<size_t>(rows) * 128);
    for (size_t k = 0; k < data.size(); ++k) data[k] = static_cast<uint8_t>(fill + k);
    sqlite3_bind_int(s, 1, id);
    sqlite3_bind_int(s, 2, rows);
    sqlite3_bind_blob(s, 3, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    ASSERT_EQ(sqlite3_step(s), SQLITE_DONE);
    sqlite3_finalize(s);
  }
  std::string dir_, path_;
};

TEST_F(ColmapDatabaseTest, ReadsImagesSortedByNameWithDescriptors) {
  const std::vector<DatabaseImage> im = ReadDatabaseImages(path_);
  ASSERT_EQ(im.size(), 4u);
  EXPECT_EQ(im[0].name, "a.jpg");
  EXPECT_EQ(im[0].image_id, 9);
  EXPECT_EQ(im[0].descriptors.rows, 1);
  EXPECT_EQ(im[0].descriptors.data[1], 8);
  EXPECT_EQ(im[1].name, "b photo.jpg");
  EXPECT_EQ(im[1].descriptors.rows, 2);
  EXPECT_EQ(im[1].descriptors.data.size(), 256u);
  EXPECT_EQ(im[2].descriptors.rows, 3);
  EXPECT_EQ(im[3].name, "d.jpg");
  EXPECT_EQ(im[3].descriptors.rows, 0);
}

TEST_F(ColmapDatabaseTest, WritesMatchesInColmapsPairOrder) {
  // (9, 5): COLMAP stores the pair as (5, 9) with the columns swapped.
  WriteDatabaseMatches(path_, {{9, 5}, {2, 5}, {2, 4}}, {{{0, 1}, {0, 0}}, {{2, 1}}, {}});
  EXPECT_EQ(ColmapPairId(9, 5), ColmapPairId(5, 9));
  EXPECT_EQ(ColmapPairId(5, 9), 2147483647LL * 5 + 9);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* s = nullptr;
  sqlite3_prepare_v2(db, "SELECT rows, cols, data FROM matches WHERE pair_id = ?", -1, &s, nullptr);
  auto read = [&](int64_t id) {
    sqlite3_bind_int64(s, 1, id);
    std::vector<uint32_t> v;
    if (sqlite3_step(s) == SQLITE_ROW) {
      EXPECT_EQ(sqlite3_column_int(s, 1), 2);
      const int rows = sqlite3_column_int(s, 0);
      const auto* p = static_cast<const uint32_t*>(sqlite3_column_blob(s, 2));
      EXPECT_EQ(sqlite3_column_bytes(s, 2), rows * 8);
      v.assign(p, p + 2 * rows);
    } else {
      v.push_back(999);  // No row.
    }
    sqlite3_reset(s);
    return v;
  };
  EXPECT_EQ(read(ColmapPairId(5, 9)), (std::vector<uint32_t>{1, 0, 0, 0}));
  EXPECT_EQ(read(ColmapPairId(2, 5)), (std::vector<uint32_t>{2, 1}));
  EXPECT_EQ(read(ColmapPairId(2, 4)), std::vector<uint32_t>{});  // Stored, empty.
  sqlite3_finalize(s);
  sqlite3_close(db);
  // Writing again replaces.
  WriteDatabaseMatches(path_, {{5, 9}}, {{{1, 1}}});
  ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
  sqlite3_prepare_v2(db, "SELECT COUNT(*), SUM(rows) FROM matches", -1, &s, nullptr);
  ASSERT_EQ(sqlite3_step(s), SQLITE_ROW);
  EXPECT_EQ(sqlite3_column_int(s, 0), 3);
  EXPECT_EQ(sqlite3_column_int(s, 1), 2);
  sqlite3_finalize(s);
  sqlite3_close(db);
}

TEST_F(ColmapDatabaseTest, ClearErrorsNamingTheFile) {
  const std::string junk = dir_ + "/junk.db";
  std::ofstream(junk) << "this is not a database at all, just some text that fills a page";
  try {
    ReadDatabaseImages(junk);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(junk), std::string::npos) << e.what();
  }
  std::remove(junk.c_str());
  EXPECT_THROW(ReadDatabaseImages(dir_ + "/missing.db"), std::runtime_error);
  // Descriptors that are not 128 wide.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
  sqlite3_exec(db, "UPDATE descriptors SET cols = 64 WHERE image_id = 5", nullptr, nullptr, nullptr);
  sqlite3_close(db);
  try {
    ReadDatabaseImages(path_);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("b photo.jpg"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace casual3d::sfm
