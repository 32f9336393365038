#include "reconstruct/eval/reference_alignment.h"

#include <filesystem>
#include <map>
#include <stdexcept>

#include "reconstruct/sfm/reference_poses.h"

namespace casual3d::eval {

namespace fs = std::filesystem;

bool HoldsColmapModel(const std::string& dir) {
  std::error_code ec;
  const fs::path d(dir);
  return fs::exists(d / "cameras.bin", ec) || fs::exists(d / "cameras.txt", ec);
}

std::string FindReferenceModel(const std::string& path) {
  std::error_code ec;
  const fs::path p(path);
  if (!fs::is_directory(p, ec))
    throw std::runtime_error(path +
                             ": not a folder (give a COLMAP model folder for the "
                             "reference poses, e.g. a synthetic capture's sparse/)");
  for (const fs::path& d : {p, p / "sparse", p / "sparse" / "0"})
    if (HoldsColmapModel(d.string())) return d.string();
  throw std::runtime_error(path + ": no COLMAP model (cameras.bin or cameras.txt) in it, in " +
                           (p / "sparse").string() + " or in " + (p / "sparse" / "0").string());
}

geometry::SparseModel PosesFromReference(const geometry::SparseModel& model,
                                         const geometry::SparseModel& reference,
                                         const std::set<std::string>& exclude,
                                         const std::string& model_label,
                                         const std::string& reference_label,
                                         ReferenceAlignment* alignment) {
  std::map<std::string, geometry::Pose> estimated, truth;
  for (const auto& [id, image] : reference.images)
    if (exclude.count(image.name) == 0) truth[image.name] = image.pose;
  int common = 0;
  for (const auto& [id, image] : model.images) {
    if (truth.count(image.name) == 0) continue;
    estimated[image.name] = image.pose;
    ++common;
  }
  if (common < 3)
    throw std::runtime_error(reference_label + ": " + std::to_string(common) +
                             (common == 1 ? " photo" : " photos") +
                             " in common with the 3D photo's model " + model_label +
                             " (by file name, the evaluated photos left out); 3 are needed to "
                             "align them");
  sfm::PoseComparison comparison;
  try {
    comparison = sfm::ComparePoses(estimated, truth);
  } catch (const std::exception& e) {
    throw std::runtime_error(reference_label + ": cannot align the 3D photo's model " +
                             model_label + " to it: " + e.what());
  }
  ReferenceAlignment a;
  a.num_common = comparison.num_common;
  a.model_to_reference = comparison.alignment;
  a.mean_rotation_error_deg = comparison.mean_rotation_error_deg;
  a.max_rotation_error_deg = comparison.max_rotation_error_deg;
  a.mean_centre_error = comparison.mean_centre_error;
  a.max_centre_error = comparison.max_centre_error;
  // The inverse similarity, x = R^T (y - t) / s, maps the reference's world
  // into the model's.
  const geometry::Similarity3& s = comparison.alignment;
  geometry::Similarity3 inverse;
  inverse.scale = 1.0 / s.scale;
  inverse.R = s.R.transpose();
  inverse.t = -(inverse.R * s.t) / s.scale;
  geometry::SparseModel out;
  out.cameras = reference.cameras;
  for (const auto& [id, image] : reference.images) {
    geometry::ModelImage mapped;
    mapped.image_id = image.image_id;
    mapped.camera_id = image.camera_id;
    mapped.name = image.name;
    mapped.pose = inverse.ApplyToPose(image.pose);
    out.images[id] = std::move(mapped);
  }
  if (alignment) *alignment = a;
  return out;
}

}  // namespace casual3d::eval
