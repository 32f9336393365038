#include "reconstruct/pipeline/holdout.h"

#include <algorithm>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "base/atomic_file.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/pipeline/panorama_stage.h"
#include "reconstruct/sfm/scene_setup.h"

namespace casual3d::pipeline {

namespace fs = std::filesystem;

std::vector<std::string> HoldoutNames(std::vector<std::string> names, int every) {
  std::vector<std::string> out;
  if (every <= 0) return out;
  std::sort(names.begin(), names.end());
  for (size_t i = 0; i < names.size(); i += every) out.push_back(names[i]);
  if (names.size() - out.size() < 2)
    throw std::invalid_argument("holdout_every " + std::to_string(every) + " leaves " +
                                std::to_string(names.size() - out.size()) + " of " +
                                std::to_string(names.size()) +
                                " registered photos for reconstruction (at least 2 needed)");
  return out;
}

void WriteTrainingWorkspace(const std::string& sparse_dir, const std::vector<std::string>& holdout,
                            const std::string& train_dir) {
  const fs::path src(sparse_dir);
  const fs::path dst(train_dir);
  const fs::path tmp = base::TemporaryPathFor(dst.string());
  std::error_code ec;
  fs::remove_all(tmp, ec);
  fs::create_directories(tmp / "sparse", ec);
  fs::create_directories(tmp / "images", ec);
  if (ec)
    throw std::runtime_error(tmp.string() + ": cannot create the training workspace (" +
                             ec.message() + ")");

  geometry::SparseModel model = geometry::ReadModel((src / "sparse").string());
  // The frame from all registered cameras, before any is removed.
  if (!fs::exists(src / "frame.json", ec))
    sfm::WritePanoramaFrame(LoadOrComputeFrame(sparse_dir), (tmp / "frame.json").string());

  const std::set<std::string> held(holdout.begin(), holdout.end());
  std::set<int> removed;
  for (auto it = model.images.begin(); it != model.images.end();) {
    if (held.count(it->second.name)) {
      removed.insert(it->first);
      it = model.images.erase(it);
    } else {
      ++it;
    }
  }
  std::set<uint64_t> dropped;
  for (auto it = model.points.begin(); it != model.points.end();) {
    auto& track = it->second.track;
    track.erase(std::remove_if(
                    track.begin(), track.end(),
                    [&](const geometry::TrackElement& t) { return removed.count(t.image_id) > 0; }),
                track.end());
    if (track.size() < 2) {
      dropped.insert(it->first);
      it = model.points.erase(it);
    } else {
      ++it;
    }
  }
  for (auto& [id, image] : model.images)
    for (auto& obs : image.points2d)
      if (obs.point3d_id != geometry::kInvalidPoint3DId && dropped.count(obs.point3d_id))
        obs.point3d_id = geometry::kInvalidPoint3DId;
  geometry::WriteModelBinary(model, (tmp / "sparse").string());

  for (const auto& entry : fs::directory_iterator(src, ec)) {
    if (entry.is_regular_file()) fs::copy_file(entry.path(), tmp / entry.path().filename(), ec);
    if (ec) throw std::runtime_error(entry.path().string() + ": cannot copy into " + tmp.string());
  }
  for (const auto& [id, image] : model.images) {
    const fs::path from = fs::absolute(src / "images" / image.name);
    const fs::path to = tmp / "images" / image.name;
    fs::create_directories(to.parent_path(), ec);
    fs::create_symlink(from, to, ec);
    if (ec) {
      ec.clear();
      fs::copy_file(from, to, ec);
      if (ec) throw std::runtime_error(from.string() + ": cannot link or copy into " + to.string());
    }
  }
  const Status moved = base::ReplaceFolder(tmp.string(), dst.string());
  if (!moved.ok()) throw std::runtime_error(moved.message());
}

}  // namespace casual3d::pipeline
