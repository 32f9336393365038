#include "reconstruct/sfm/scene_setup.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <nlohmann/json.hpp>

#include "reconstruct/io/file_util.h"

namespace casual3d::sfm {
namespace {

using Json = nlohmann::json;

constexpr const char* kDepthRangesFormat = "casual3d-depth-ranges";
constexpr const char* kFrameFormat = "casual3d-panorama-frame";
constexpr int kMajorVersion = 1;
constexpr const char* kVersion = "1.0";

// Value at fraction p of the sorted values, linearly interpolated.
double Percentile(const std::vector<double>& sorted, double p) {
  if (sorted.size() == 1) return sorted[0];
  const double pos = p * static_cast<double>(sorted.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, sorted.size() - 1);
  const double w = pos - static_cast<double>(lo);
  return sorted[lo] * (1.0 - w) + sorted[hi] * w;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return Percentile(v, 0.5);
}

// Camera centre, viewing direction (camera +Z) and up (camera -Y) in world
// coordinates from a world-to-camera pose.
Eigen::Vector3d CentreOf(const geometry::Pose& pose) {
  return -(pose.R().transpose() * pose.translation);
}
Eigen::Vector3d ViewOf(const geometry::Pose& pose) { return pose.R().row(2).transpose(); }
Eigen::Vector3d UpOf(const geometry::Pose& pose) { return -pose.R().row(1).transpose(); }

// The positions of the model points that at least `min_track` photos observe.
std::vector<Eigen::Vector3d> PointsSeenBy(const geometry::SparseModel& model, size_t min_track) {
  std::vector<Eigen::Vector3d> points;
  for (const auto& [id, point] : model.points)
    if (point.track.size() >= min_track) points.push_back(point.xyz);
  return points;
}

// Camera-frame depths of those of `points` that lie in front of `image` and
// project inside its pinhole view.
std::vector<double> FrustumDepths(const std::vector<Eigen::Vector3d>& points, const geometry::SparseModel& model,
                                  const geometry::ModelImage& image) {
  std::vector<double> depths;
  const auto cam_it = model.cameras.find(image.camera_id);
  if (cam_it == model.cameras.end() || cam_it->second.width <= 0) return depths;
  const geometry::Camera pinhole = cam_it->second.PinholePart();
  const Eigen::Matrix3d R = image.pose.R();
  const Eigen::Vector3d& t = image.pose.translation;
  for (const Eigen::Vector3d& xyz : points) {
    const Eigen::Vector3d p = R * xyz + t;
    if (!(p.z() > 0)) continue;
    const Eigen::Vector2d uv = pinhole.Project(p);
    if (uv.x() >= 0 && uv.x() <= pinhole.width && uv.y() >= 0 && uv.y() <= pinhole.height) depths.push_back(p.z());
  }
  return depths;
}

DepthRange RangeFromDepths(std::vector<double> depths, const DepthRangeOptions& options) {
  std::sort(depths.begin(), depths.end());
  DepthRange r;
  r.num_points = static_cast<int>(depths.size());
  r.far_m = Percentile(depths, options.far_percentile) * options.far_margin;
  r.near_m = Percentile(depths, options.near_percentile) * options.near_margin;
  r.near_m = std::max(r.near_m, r.far_m * options.min_near_over_far);
  if (!(r.far_m > r.near_m)) r.far_m = r.near_m * 2.0;  // All points at one depth.
  return r;
}

int ParseMajor(const Json& j, const std::string& path, const char* expected_format) {
  if (!j.is_object()) throw std::runtime_error(path + ": not a JSON object");
  if (!j.contains("format") || !j["format"].is_string() ||
      j["format"].get<std::string>() != expected_format) {
    throw std::runtime_error(path + ": field 'format' is not \"" + std::string(expected_format) +
                             "\"");
  }
  if (!j.contains("version") || !j["version"].is_string()) {
    throw std::runtime_error(path + ": missing string field 'version'");
  }
  const std::string v = j["version"].get<std::string>();
  int major = 0;
  int minor = 0;
  char dot = 0;
  std::istringstream ss(v);
  if (!(ss >> major >> dot >> minor) || dot != '.') {
    throw std::runtime_error(path + ": field 'version' \"" + v + "\" is not MAJOR.MINOR");
  }
  if (major != kMajorVersion) {
    throw std::runtime_error(path + ": unsupported major version " + std::to_string(major) +
                             " (this program reads " + std::to_string(kMajorVersion) + ".x)");
  }
  return major;
}

double GetNumber(const Json& j, const char* key, const std::string& where) {
  if (!j.contains(key) || !j[key].is_number()) {
    throw std::runtime_error(where + ": missing number field '" + key + "'");
  }
  const double v = j[key].get<double>();
  if (!std::isfinite(v)) throw std::runtime_error(where + ": field '" + key + "' is not finite");
  return v;
}

Json ParseJsonFile(const std::string& path) {
  const std::string text = io::ReadFile(path);
  Json j = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) throw std::runtime_error(path + ": not valid JSON");
  return j;
}

}  // namespace

std::map<int, DepthRange> ComputeDepthRanges(const geometry::SparseModel& model,
                                             const DepthRangeOptions& options) {
  const Status status = options.Check();
  if (!status.ok()) throw std::invalid_argument("depth range options: " + status.message());
  if (model.images.empty()) throw std::runtime_error("depth ranges: the model has no photos");

  std::map<int, DepthRange> ranges;
  std::vector<int> unresolved;
  // Every point, for photos that observe too few (read when one needs them),
  // and the points of three or more photos, for the near bound.
  std::vector<Eigen::Vector3d> all_points;
  const size_t k = static_cast<size_t>(options.frustum_near_points);
  const std::vector<Eigen::Vector3d> multi_view_points =
      k > 0 ? PointsSeenBy(model, 3) : std::vector<Eigen::Vector3d>();
  for (const auto& [image_id, image] : model.images) {
    const Eigen::Matrix3d R = image.pose.R();
    const Eigen::Vector3d& t = image.pose.translation;
    std::vector<double> depths;
    for (const geometry::Observation2D& obs : image.points2d) {
      if (obs.point3d_id == geometry::kInvalidPoint3DId) continue;
      const auto it = model.points.find(obs.point3d_id);
      if (it == model.points.end()) continue;
      const double z = R.row(2).dot(it->second.xyz) + t.z();
      if (z > 0 && std::isfinite(z)) depths.push_back(z);
    }
    std::string source = "observed";
    if (static_cast<int>(depths.size()) < options.min_points) {
      // Too few observations (a weakly registered photo): fall back to every
      // model point that projects inside its pinhole view.
      if (all_points.empty()) all_points = PointsSeenBy(model, 0);
      depths = FrustumDepths(all_points, model, image);
      source = "frustum";
    }
    if (static_cast<int>(depths.size()) < options.min_points) {
      unresolved.push_back(image_id);
      continue;
    }
    DepthRange r = RangeFromDepths(std::move(depths), options);
    if (k > 0 && source == "observed") {
      std::vector<double> frustum = FrustumDepths(multi_view_points, model, image);
      if (frustum.size() >= k) {
        std::nth_element(frustum.begin(), frustum.begin() + (k - 1), frustum.end());
        const double near_m = std::max(frustum[k - 1] * options.near_margin, r.far_m * options.min_near_over_far);
        r.near_m = std::min(r.near_m, near_m);
      }
    }
    r.name = image.name;
    r.source = source;
    ranges[image_id] = r;
  }
  if (ranges.empty()) {
    throw std::runtime_error("depth ranges: no photo sees at least " +
                             std::to_string(options.min_points) +
                             " sparse points in front of it; the reconstruction is too sparse");
  }
  if (!unresolved.empty()) {
    // The median of the others is a safe sweep range for the stragglers: the
    // photos of one capture see the same scene from nearby viewpoints.
    std::vector<double> nears, fars;
    for (const auto& [id, r] : ranges) {
      nears.push_back(r.near_m);
      fars.push_back(r.far_m);
    }
    const double near_m = Median(nears);
    const double far_m = std::max(Median(fars), near_m * 2.0);
    for (int image_id : unresolved) {
      DepthRange r;
      r.name = model.images.at(image_id).name;
      r.near_m = near_m;
      r.far_m = far_m;
      r.num_points = 0;
      r.source = "global";
      ranges[image_id] = r;
    }
  }
  return ranges;
}

PanoramaFrame ComputePanoramaFrame(const geometry::SparseModel& model,
                                   const PanoramaFrameOptions& options, PanoramaFrameInfo* info) {
  const Status status = options.Check();
  if (!status.ok()) throw std::invalid_argument("panorama frame options: " + status.message());
  if (model.images.empty()) throw std::runtime_error("panorama frame: the model has no photos");

  std::vector<Eigen::Vector3d> centres;
  Eigen::Vector3d up_sum = Eigen::Vector3d::Zero();
  for (const auto& [id, image] : model.images) {
    centres.push_back(CentreOf(image.pose));
    up_sum += UpOf(image.pose);
  }
  const double n = static_cast<double>(centres.size());

  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& c : centres) centre += c;
  centre /= n;
  if (options.robust_centre && centres.size() > 2) {
    // Weiszfeld's iteration for the geometric median, started at the mean.
    for (int iter = 0; iter < 200; ++iter) {
      Eigen::Vector3d num = Eigen::Vector3d::Zero();
      double den = 0.0;
      for (const auto& c : centres) {
        const double d = std::max((c - centre).norm(), 1e-12);
        num += c / d;
        den += 1.0 / d;
      }
      const Eigen::Vector3d next = num / den;
      const double step = (next - centre).norm();
      centre = next;
      if (step < 1e-12) break;
    }
  }

  // Up: the mean camera up. Hand-held photos are mostly taken upright, so this
  // is the gravity direction up to the capture's small tilts.
  if (up_sum.norm() < 0.1 * n) {
    throw std::runtime_error(
        "panorama frame: the photos' up directions cancel out (photos rotated in every "
        "direction); cannot tell which way is up");
  }
  const Eigen::Vector3d up = up_sum.normalized();

  // Forward: the mean horizontal viewing direction for a partial capture.
  Eigen::Vector3d forward_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d first_forward = Eigen::Vector3d::Zero();
  int num_horizontal = 0;
  for (const auto& [id, image] : model.images) {  // Ordered by image_id.
    const Eigen::Vector3d v = ViewOf(image.pose);
    const Eigen::Vector3d h = v - v.dot(up) * up;
    if (h.norm() < 1e-6) continue;  // Looks straight up or down.
    if (num_horizontal == 0) first_forward = h.normalized();
    forward_sum += h.normalized();
    ++num_horizontal;
  }
  double resultant = 0.0;
  Eigen::Vector3d forward;
  if (num_horizontal == 0) {
    // Every photo looks along the up axis: any horizontal direction will do.
    forward = up.unitOrthogonal();
  } else {
    resultant = forward_sum.norm() / num_horizontal;
    forward = (resultant >= options.min_partial_resultant && resultant > 1e-9)
                  ? forward_sum.normalized()
                  : first_forward;
  }
  forward = (forward - forward.dot(up) * up).normalized();
  const Eigen::Vector3d right = forward.cross(up).normalized();
  const Eigen::Vector3d back = -forward;

  PanoramaFrame frame;
  for (int k = 0; k < 3; ++k) {
    frame.centre[k] = centre[k];
    frame.rotation[0 + k] = right[k];
    frame.rotation[3 + k] = up[k];
    frame.rotation[6 + k] = back[k];
  }
  if (info != nullptr) {
    info->centre = centre;
    info->up = up;
    info->forward = forward;
    info->resultant = resultant;
    info->full_capture = num_horizontal > 0 && resultant < options.min_partial_resultant;
    info->num_cameras = static_cast<int>(centres.size());
    double r = 0.0;
    for (const auto& c : centres) r += (c - centre).norm();
    info->rig_radius = r / n;
  }
  return frame;
}

Eigen::Matrix3d FrameRotation(const PanoramaFrame& frame) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R(r, c) = frame.rotation[3 * r + c];
  }
  return R;
}

Eigen::Vector3d FrameCentre(const PanoramaFrame& frame) {
  return {frame.centre[0], frame.centre[1], frame.centre[2]};
}

Eigen::Vector3d WorldToPanorama(const PanoramaFrame& frame, const Eigen::Vector3d& p_world) {
  return FrameRotation(frame) * (p_world - FrameCentre(frame));
}

void WriteDepthRanges(const std::map<int, DepthRange>& ranges, const std::string& path) {
  Json images = Json::array();
  for (const auto& [image_id, r] : ranges) {
    images.push_back({{"image_id", image_id},
                      {"name", r.name},
                      {"near_m", r.near_m},
                      {"far_m", r.far_m},
                      {"num_points", r.num_points},
                      {"source", r.source}});
  }
  Json j = {{"format", kDepthRangesFormat},
            {"version", kVersion},
            {"depth", "camera-frame z along the optical axis, in model units"},
            {"images", images}};
  io::WriteFileAtomic(path, j.dump(2) + "\n");
}

std::map<int, DepthRange> ReadDepthRanges(const std::string& path) {
  const Json j = ParseJsonFile(path);
  ParseMajor(j, path, kDepthRangesFormat);
  if (!j.contains("images") || !j["images"].is_array()) {
    throw std::runtime_error(path + ": missing array field 'images'");
  }
  std::map<int, DepthRange> ranges;
  for (size_t i = 0; i < j["images"].size(); ++i) {
    const Json& e = j["images"][i];
    const std::string where = path + ": images[" + std::to_string(i) + "]";
    if (!e.is_object()) throw std::runtime_error(where + ": not an object");
    if (!e.contains("image_id") || !e["image_id"].is_number_integer()) {
      throw std::runtime_error(where + ": missing integer field 'image_id'");
    }
    if (!e.contains("name") || !e["name"].is_string()) {
      throw std::runtime_error(where + ": missing string field 'name'");
    }
    DepthRange r;
    const int image_id = e["image_id"].get<int>();
    r.name = e["name"].get<std::string>();
    r.near_m = GetNumber(e, "near_m", where);
    r.far_m = GetNumber(e, "far_m", where);
    if (!(r.near_m > 0 && r.far_m > r.near_m)) {
      throw std::runtime_error(where + ": needs 0 < near_m < far_m");
    }
    if (e.contains("num_points") && e["num_points"].is_number_integer()) {
      r.num_points = e["num_points"].get<int>();
    }
    if (e.contains("source") && e["source"].is_string()) r.source = e["source"].get<std::string>();
    if (!ranges.emplace(image_id, r).second) {
      throw std::runtime_error(where + ": duplicate image_id " + std::to_string(image_id));
    }
  }
  return ranges;
}

void WritePanoramaFrame(const PanoramaFrame& frame, const std::string& path,
                        const PanoramaFrameInfo* info) {
  Json j = {{"format", kFrameFormat},
            {"version", kVersion},
            {"convention",
             "p_panorama = rotation * (p_world - centre); rotation row-major; panorama "
             "+X right, +Y up, -Z forward"},
            {"centre", {frame.centre[0], frame.centre[1], frame.centre[2]}},
            {"rotation", std::vector<double>(frame.rotation, frame.rotation + 9)}};
  if (info != nullptr) {
    j["info"] = {{"up", {info->up.x(), info->up.y(), info->up.z()}},
                 {"forward", {info->forward.x(), info->forward.y(), info->forward.z()}},
                 {"resultant", info->resultant},
                 {"full_capture", info->full_capture},
                 {"num_cameras", info->num_cameras},
                 {"rig_radius", info->rig_radius}};
  }
  io::WriteFileAtomic(path, j.dump(2) + "\n");
}

PanoramaFrame ReadPanoramaFrame(const std::string& path) {
  const Json j = ParseJsonFile(path);
  ParseMajor(j, path, kFrameFormat);
  auto read_array = [&](const char* key, size_t count, double* out) {
    if (!j.contains(key) || !j[key].is_array() || j[key].size() != count) {
      throw std::runtime_error(path + ": field '" + key + "' must be an array of " +
                               std::to_string(count) + " numbers");
    }
    for (size_t i = 0; i < count; ++i) {
      if (!j[key][i].is_number() || !std::isfinite(j[key][i].get<double>())) {
        throw std::runtime_error(path + ": field '" + key + "' holds a non-number");
      }
      out[i] = j[key][i].get<double>();
    }
  };
  PanoramaFrame frame;
  read_array("centre", 3, frame.centre);
  read_array("rotation", 9, frame.rotation);
  const Eigen::Matrix3d R = FrameRotation(frame);
  if ((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
      std::abs(R.determinant() - 1.0) > 1e-6) {
    throw std::runtime_error(path + ": field 'rotation' is not a rotation (orthonormal, det +1)");
  }
  return frame;
}

}  // namespace casual3d::sfm
