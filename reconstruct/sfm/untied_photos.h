#pragma once

// Photos the mapper registered but nothing ties to the others: COLMAP
// registers a photo from its matches to the model's points, and later
// filtering (retriangulation, outlier removal in bundle adjustment) can take
// away almost all of the points it sees. Its pose then drifts freely (seen:
// frames of a video placed 1e5 units from the others), and one such pose
// moves the 3D photo's frame and depth ranges. The sparse stage leaves them
// out as unregistered (SparseStageOptions::min_photo_points).

#include <string>
#include <vector>

#include "reconstruct/geometry/colmap_model.h"

namespace casual3d::sfm {

struct UntiedPhoto {
  std::string name;
  int points = 0;  // 3D points the photo sees.
};

// Removes from `model` the images that see fewer than `min_points` 3D points,
// their observations from the points' tracks, and the points left with
// fewer than 2 observations (references to them in the other images become
// invalid). Returns the removed images in image-id order.
std::vector<UntiedPhoto> DropUntiedPhotos(int min_points, geometry::SparseModel* model);

}  // namespace casual3d::sfm
