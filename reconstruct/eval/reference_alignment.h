#pragma once

// Poses of photos that a 3D photo's own model does not hold, for virtual
// rephotography (evaluate.h, EvaluateOptions::reference_poses). A 3D photo
// made from a video's frames has no pose for the photos held out of it; a
// reference model that holds both (a synthetic capture's ground truth,
// synth/clip.h, or one structure-from-motion run over the photos and the
// frames together) gives them. The 3D photo's model is aligned to the
// reference by a similarity over the photos (frames) both hold, matched by
// name (sfm/reference_poses.h ComparePoses), and the reference's poses are
// mapped through its inverse into the 3D photo's world.

#include <set>
#include <string>

#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/geometry/pose.h"

namespace casual3d::eval {

struct ReferenceAlignment {
  int num_common = 0;  // Photos used to align (in both models, not excluded).
  // Maps the 3D photo's model's world into the reference's: y = s R x + t.
  geometry::Similarity3 model_to_reference;
  // Residuals of the aligned common photos: orientation in degrees, camera
  // centre in the reference's units.
  double mean_rotation_error_deg = 0, max_rotation_error_deg = 0;
  double mean_centre_error = 0, max_centre_error = 0;
};

// Whether `dir` holds a COLMAP model (cameras.bin or cameras.txt).
bool HoldsColmapModel(const std::string& dir);

// The folder holding a COLMAP model (cameras.bin or cameras.txt) for `path`:
// the folder itself, else its sparse/ or sparse/0. Throws std::runtime_error
// naming `path` when none holds one.
std::string FindReferenceModel(const std::string& path);

// `reference` with every image's pose mapped into `model`'s world, after
// aligning `model` to `reference` over the image names both hold except
// those in `exclude` (the photos being evaluated, so that their own
// estimated poses do not pull the alignment). Cameras are the reference's.
// Throws std::runtime_error with one line naming `reference_label` and
// `model_label` when fewer than 3 names are common, or when their camera
// centres coincide.
geometry::SparseModel PosesFromReference(const geometry::SparseModel& model,
                                         const geometry::SparseModel& reference,
                                         const std::set<std::string>& exclude,
                                         const std::string& model_label,
                                         const std::string& reference_label,
                                         ReferenceAlignment* alignment);

}  // namespace casual3d::eval
