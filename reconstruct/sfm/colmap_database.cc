#include "reconstruct/sfm/colmap_database.h"

#include <sqlite3.h>

#include <algorithm>
#include <stdexcept>

namespace casual3d::sfm {
namespace {

constexpr int64_t kMaxNumImages = 2147483647;  // COLMAP's pair-id base.

class Db {
 public:
  Db(const std::string& path, bool write) : path_(path) {
    const int flags = write ? SQLITE_OPEN_READWRITE : SQLITE_OPEN_READONLY;
    if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
      const std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      db_ = nullptr;
      throw std::runtime_error(path + ": cannot open the COLMAP database: " + msg);
    }
    sqlite3_busy_timeout(db_, 10000);
  }
  ~Db() {
    for (sqlite3_stmt* s : statements_) sqlite3_finalize(s);
    sqlite3_close(db_);
  }
  Db(const Db&) = delete;
  Db& operator=(const Db&) = delete;

  // Throws "<path>: <what>: <SQLite's reason> (<hint>)".
  [[noreturn]] void Fail(const std::string& what,
                         const char* hint = "not a COLMAP database, or damaged") const {
    throw std::runtime_error(path_ + ": " + what + ": " + sqlite3_errmsg(db_) + " (" + hint + ")");
  }
  sqlite3_stmt* Prepare(const char* sql) {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db_, sql, -1, &s, nullptr) != SQLITE_OK) Fail("cannot read");
    statements_.push_back(s);
    return s;
  }
  void Exec(const char* sql, const char* what, const char* hint) {
    if (sqlite3_exec(db_, sql, nullptr, nullptr, nullptr) != SQLITE_OK) Fail(what, hint);
  }

 private:
  std::string path_;
  sqlite3* db_ = nullptr;
  std::vector<sqlite3_stmt*> statements_;
};

}  // namespace

int64_t ColmapPairId(int64_t image_id1, int64_t image_id2) {
  if (image_id1 > image_id2) std::swap(image_id1, image_id2);
  return kMaxNumImages * image_id1 + image_id2;
}

std::vector<DatabaseImage> ReadDatabaseImages(const std::string& db_path) {
  Db db(db_path, false);
  sqlite3_stmt* s = db.Prepare(
      "SELECT images.image_id, images.name, descriptors.rows, descriptors.cols, descriptors.data "
      "FROM images LEFT JOIN descriptors ON images.image_id = descriptors.image_id");
  std::vector<DatabaseImage> images;
  int rc;
  while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
    DatabaseImage im;
    im.image_id = sqlite3_column_int64(s, 0);
    const unsigned char* name = sqlite3_column_text(s, 1);
    im.name = name ? reinterpret_cast<const char*>(name) : "";
    if (sqlite3_column_type(s, 2) != SQLITE_NULL) {
      const int64_t rows = sqlite3_column_int64(s, 2), cols = sqlite3_column_int64(s, 3);
      const int bytes = sqlite3_column_bytes(s, 4);
      const void* blob = sqlite3_column_blob(s, 4);
      if (rows < 0 || rows > (int64_t{1} << 24) || (rows > 0 && cols != kSiftDimensions) ||
          bytes != rows * cols || (bytes > 0 && blob == nullptr))
        throw std::runtime_error(db_path + ": descriptors of image '" + im.name + "' are " +
                                 std::to_string(rows) + " x " + std::to_string(cols) + " in " +
                                 std::to_string(bytes) + " bytes, not N x 128 SIFT bytes");
      im.descriptors.rows = static_cast<int>(rows);
      const auto* p = static_cast<const uint8_t*>(blob);
      im.descriptors.data.assign(p, p + bytes);
    }
    images.push_back(std::move(im));
  }
  if (rc != SQLITE_DONE) db.Fail("cannot read the images");
  std::sort(images.begin(), images.end(),
            [](const DatabaseImage& a, const DatabaseImage& b) { return a.name < b.name; });
  return images;
}

void WriteDatabaseMatches(const std::string& db_path,
                          const std::vector<std::pair<int64_t, int64_t>>& image_pairs,
                          const std::vector<FeatureMatches>& matches) {
  if (image_pairs.size() != matches.size())
    throw std::invalid_argument("WriteDatabaseMatches: one match list per pair");
  // Closing the connection with the transaction open (any throw below)
  // rolls it back: nothing is written.
  Db db(db_path, true);
  db.Exec("BEGIN IMMEDIATE", "cannot write", "is another program using it?");
  sqlite3_stmt* s =
      db.Prepare("INSERT OR REPLACE INTO matches (pair_id, rows, cols, data) VALUES (?, ?, 2, ?)");
  std::vector<uint32_t> blob;
  for (size_t k = 0; k < image_pairs.size(); ++k) {
    auto [id1, id2] = image_pairs[k];
    if (id1 == id2) throw std::invalid_argument("WriteDatabaseMatches: pair of an image with itself");
    const bool swapped = id1 > id2;
    blob.clear();
    for (const auto& [i, j] : matches[k]) {
      blob.push_back(swapped ? j : i);
      blob.push_back(swapped ? i : j);
    }
    sqlite3_bind_int64(s, 1, ColmapPairId(id1, id2));
    sqlite3_bind_int64(s, 2, static_cast<int64_t>(matches[k].size()));
    if (blob.empty()) {
      sqlite3_bind_zeroblob(s, 3, 0);  // Zero matches, stored: COLMAP does not match the pair again.
    } else {
      sqlite3_bind_blob(s, 3, blob.data(), static_cast<int>(blob.size() * sizeof(uint32_t)),
                        SQLITE_TRANSIENT);
    }
    if (sqlite3_step(s) != SQLITE_DONE) db.Fail("cannot store matches", "disk full?");
    sqlite3_reset(s);
  }
  db.Exec("COMMIT", "cannot store matches", "disk full?");
}

}  // namespace casual3d::sfm
