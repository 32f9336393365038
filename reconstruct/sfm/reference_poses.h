#pragma once

// Reference camera poses of public datasets, and the comparison of a
// reconstruction against them after a similarity alignment. Used by the sparse
// stage's accuracy tests:
//  - LLFF's poses_bounds.npy (fern): N rows of 17 float64 values, a 3x5 matrix
//    [R | t | (height, width, focal)] flattened row-major followed by the near
//    and far depth bounds. [R | t] is camera-to-world with camera axes
//    (down, right, back); rows follow the sorted image names.
//  - Strecha's *.camera files (fountain-P11): K (3 rows), a row of 3 distortion
//    terms (zero), R (3 rows), the camera centre C and "width height". The
//    projection is K R^T (X - C), i.e. R's columns are the camera axes in world
//    coordinates (camera-to-world rotation).
//  - NumPy .npy files (version 1 to 3, little-endian float32/float64, C order).

#include <map>
#include <string>
#include <vector>

#include "reconstruct/geometry/pose.h"

namespace casual3d::sfm {

struct NpyArray {
  std::vector<size_t> shape;
  std::vector<double> data;  // Row-major, converted to double.
};

// Reads a .npy file; throws std::runtime_error naming the file and the problem
// (bad magic, unsupported dtype or Fortran order, truncated data).
NpyArray ReadNpy(const std::string& path);

struct ReferenceCamera {
  geometry::Pose pose;  // World to camera, COLMAP's camera axes (+X right, +Y down, +Z forward).
  int width = 0;        // Pixels.
  int height = 0;       // Pixels.
  double focal_px = 0;  // Focal length in pixels at width x height (fx for Strecha).
};

// Reads LLFF's poses_bounds.npy; `image_names` are the photos in sorted order,
// one per row. Throws std::runtime_error if the array is not N x 17 with N =
// image_names.size().
std::map<std::string, ReferenceCamera> ReadLlffPosesBounds(
    const std::string& path, const std::vector<std::string>& image_names);

// Reads one Strecha camera file. Throws std::runtime_error naming the file on
// malformed content or a non-rotation R.
ReferenceCamera ReadStrechaCamera(const std::string& path);
// Reads every "<image name>.camera" file of a folder, keyed by image name.
std::map<std::string, ReferenceCamera> ReadStrechaCameras(const std::string& dir);

struct PoseComparison {
  int num_common = 0;  // Photos present in both (the others are ignored).
  geometry::Similarity3 alignment;  // Maps the estimate's world into the reference's.
  double max_rotation_error_deg = 0;
  double mean_rotation_error_deg = 0;
  double max_centre_error = 0;   // Reference units, after alignment.
  double mean_centre_error = 0;  // Reference units, after alignment.
  // Largest distance between two reference camera centres (reference units).
  double reference_spread = 0;
};

// Aligns the estimate to the reference by a similarity y = s R x + t: R is the
// chordal mean of the photos' relative rotations (R_ref^T R_est), s and t the
// least-squares fit of the camera centres given R. Then reports rotation and
// centre errors of the aligned estimate. Throws std::runtime_error if fewer
// than 3 photos are common or the centres all coincide.
PoseComparison ComparePoses(const std::map<std::string, geometry::Pose>& estimated,
                            const std::map<std::string, geometry::Pose>& reference);

}  // namespace casual3d::sfm
