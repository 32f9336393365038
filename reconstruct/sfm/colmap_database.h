#pragma once

// Reading features from and writing matches into a COLMAP database (SQLite,
// the schema of COLMAP 3.x: tables images, descriptors and matches). The
// sparse stage matches descriptors itself (descriptor_matcher.h), stores the
// matches, and COLMAP's matcher then only verifies them geometrically: it
// skips the descriptor matching of every pair whose matches exist.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "reconstruct/sfm/descriptor_matcher.h"

namespace casual3d::sfm {

struct DatabaseImage {
  int64_t image_id = 0;
  std::string name;
  SiftDescriptors descriptors;  // Empty if the image has none.
};

// Every image of the database with its SIFT descriptors, sorted by name.
// Throws std::runtime_error naming the file when it cannot be opened, is not
// a COLMAP database or holds descriptors that are not 128 bytes wide.
std::vector<DatabaseImage> ReadDatabaseImages(const std::string& db_path);

// COLMAP's identifier of an unordered image pair.
int64_t ColmapPairId(int64_t image_id1, int64_t image_id2);

// Stores matches[i] (indices into image_pairs[i].first's and .second's
// features) as the raw matches of that pair, replacing any, in one
// transaction. Throws std::runtime_error naming the file on failure (nothing
// is written then).
void WriteDatabaseMatches(const std::string& db_path,
                          const std::vector<std::pair<int64_t, int64_t>>& image_pairs,
                          const std::vector<FeatureMatches>& matches);

}  // namespace casual3d::sfm
