#include "reconstruct/sfm/untied_photos.h"

#include <algorithm>
#include <map>
#include <set>

namespace casual3d::sfm {

std::vector<UntiedPhoto> DropUntiedPhotos(int min_points, geometry::SparseModel* model) {
  std::map<int, int> seen;  // Image id -> 3D points it sees.
  for (const auto& [id, point] : model->points)
    for (const geometry::TrackElement& t : point.track) ++seen[t.image_id];
  std::vector<UntiedPhoto> dropped;
  std::set<int> dropped_ids;
  for (const auto& [id, image] : model->images) {
    if (seen[id] >= min_points) continue;
    dropped.push_back({image.name, seen[id]});
    dropped_ids.insert(id);
  }
  if (dropped.empty()) return dropped;
  for (int id : dropped_ids) model->images.erase(id);
  std::set<uint64_t> gone;
  for (auto& [id, point] : model->points) {
    auto& track = point.track;
    track.erase(std::remove_if(track.begin(), track.end(),
                               [&](const geometry::TrackElement& t) {
                                 return dropped_ids.count(t.image_id) > 0;
                               }),
                track.end());
    if (track.size() < 2) gone.insert(id);
  }
  for (uint64_t id : gone) model->points.erase(id);
  for (auto& [id, image] : model->images)
    for (geometry::Observation2D& o : image.points2d)
      if (o.point3d_id != geometry::kInvalidPoint3DId && gone.count(o.point3d_id))
        o.point3d_id = geometry::kInvalidPoint3DId;
  return dropped;
}

}  // namespace casual3d::sfm
