#pragma once

// COLMAP sparse models (cameras, images, points3D) in memory, and their text
// (cameras.txt, images.txt, points3D.txt) and binary (*.bin) forms, read and
// written as COLMAP 3.8 does. Readers tolerate comments and empty lines and
// throw ModelError naming the file, the line (text) or byte offset (binary),
// and what was expected.

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "reconstruct/geometry/camera.h"
#include "reconstruct/geometry/pose.h"

namespace casual3d::geometry {

constexpr uint64_t kInvalidPoint3DId = static_cast<uint64_t>(-1);

struct Observation2D {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // Pixel, COLMAP convention.
  uint64_t point3d_id = kInvalidPoint3DId;       // kInvalidPoint3DId if none.
};

struct ModelImage {
  int image_id = 0;
  int camera_id = 0;
  std::string name;  // Relative path below the image folder.
  Pose pose;         // World to camera.
  std::vector<Observation2D> points2d;
};

struct TrackElement {
  int image_id = 0;
  int point2d_idx = 0;
};

struct Point3D {
  uint64_t point3d_id = 0;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  uint8_t rgb[3] = {0, 0, 0};
  double error = 0.0;  // Mean reprojection error, pixels.
  std::vector<TrackElement> track;
};

struct SparseModel {
  std::map<int, Camera> cameras;       // By camera_id.
  std::map<int, ModelImage> images;    // By image_id.
  std::map<uint64_t, Point3D> points;  // By point3d_id.

  const ModelImage* FindImageByName(const std::string& name) const;
};

class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads a model folder holding either cameras.bin/images.bin/points3D.bin or
// the .txt files (binary preferred when both exist).
SparseModel ReadModel(const std::string& dir);
SparseModel ReadModelText(const std::string& dir);
SparseModel ReadModelBinary(const std::string& dir);

// Single-file readers, for folders that hold only part of a model (for
// example a cameras.bin of intrinsics). Same error conventions as above.
std::map<int, Camera> ReadCamerasText(const std::string& path);
std::map<int, ModelImage> ReadImagesText(const std::string& path);
std::map<uint64_t, Point3D> ReadPoints3DText(const std::string& path);
std::map<int, Camera> ReadCamerasBinary(const std::string& path);
std::map<int, ModelImage> ReadImagesBinary(const std::string& path);
std::map<uint64_t, Point3D> ReadPoints3DBinary(const std::string& path);
// Writers create `dir` if needed and write each file atomically (temporary name, rename).
void WriteModelText(const SparseModel& model, const std::string& dir);
void WriteModelBinary(const SparseModel& model, const std::string& dir);

}  // namespace casual3d::geometry
