#include "reconstruct/pipeline/capture_shape.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "reconstruct/io/file_util.h"
#include "reconstruct/sfm/scene_setup.h"
#include "reconstruct/util/union_find.h"

namespace casual3d::pipeline {
namespace {

namespace fs = std::filesystem;

// The p-quantile (p in [0, 1]) of `values` (reordered); 0 when empty.
double Quantile(std::vector<double>* values, double p) {
  if (values->empty()) return 0.0;
  const size_t k = static_cast<size_t>(std::lround(p * (values->size() - 1)));
  std::nth_element(values->begin(), values->begin() + k, values->end());
  return (*values)[k];
}

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

std::string Percent(double fraction) { return Format("%.0f%%", 100.0 * fraction); }

// Directions spread evenly over the sphere (Fibonacci lattice).
std::vector<Eigen::Vector3d> SphereDirections(int n) {
  std::vector<Eigen::Vector3d> d(n);
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    d[i] = {r * std::cos(golden * i), r * std::sin(golden * i), z};
  }
  return d;
}

// Whether a photo sees the world direction `d` (a point at infinity).
bool Sees(const geometry::Camera& camera, const Eigen::Matrix3d& R, const Eigen::Vector3d& d) {
  const Eigen::Vector3d p = R * d;
  if (p.z() <= 1e-9) return false;
  const double u = camera.FocalX() * p.x() / p.z() + camera.PrincipalX();
  const double v = camera.FocalY() * p.y() / p.z() + camera.PrincipalY();
  return u >= 0 && u <= camera.width && v >= 0 && v <= camera.height;
}

void AddAdvice(const std::vector<std::string>& order, CaptureShape* s) {
  const bool has_near = s->near_depth > 0;
  // Lengths in metres, or as multiples of the near depth.
  const auto length = [&](double value) {
    if (s->metric) return Format("%.2f m", value);
    return has_near ? Format("%.2f times the distance to the nearest objects", value / s->near_depth)
                    : Format("%.2f model units", value);
  };
  std::string line = "The camera moved " + length(s->extent);
  if (s->metric && has_near) line += "; the nearest objects were " + Format("%.2f m", s->near_depth) + " away";
  line += "; the photos see " + Percent(s->sphere_fraction) + " of the sphere around them";
  if (s->photo_sphere_fraction > 0)
    line += " (" + Format("%.1f", s->sphere_fraction / s->photo_sphere_fraction) + " times one photo's view)";
  s->advice.push_back(line + ".");
  if (s->walked) {
    s->advice.push_back(
        "The camera moved " + length(s->extent) + (s->around ? " around the subject" : " sideways") +
        "; 3D photos are taken from one spot: stand still and turn, holding the phone at arm's "
        "length (views far from the centre will show gaps and stretched surfaces).");
  }
  if (s->narrow) {
    s->advice.push_back("The photos all look the same way (" + Percent(s->sphere_fraction) +
                        " of the sphere); turn left-right and up-down between photos to cover a wider view.");
  }
  for (size_t g = 1; g < s->groups.size(); ++g) {
    const bool one = s->groups[g].size() == 1;
    const std::string who = (one ? "Photo " : "Photos ") + NameRuns(s->groups[g], order);
    if (s->group_links[g - 1] == 0) {
      s->advice.push_back(who + (one ? " overlaps" : " overlap") +
                          " nothing the other photos saw: take " + (one ? "it" : "them") +
                          " with more overlap (about two thirds with each neighbour).");
    } else {
      s->advice.push_back(who + (one ? " is" : " are") + " tied to the other photos by only " +
                          std::to_string(s->group_links[g - 1]) + " shared points: take " +
                          (one ? "it" : "them") +
                          " with more overlap (about two thirds with each neighbour).");
    }
  }
  if (!s->unregistered.empty()) {
    const bool one = s->unregistered.size() == 1;
    s->advice.push_back((one ? "Photo " : "Photos ") + NameRuns(s->unregistered, order) +
                        (one ? " overlaps" : " overlap") +
                        " nothing the other photos saw and " + (one ? "was" : "were") +
                        " left out: take " + (one ? "it" : "them") +
                        " with more overlap (about two thirds with each neighbour).");
  }
}

}  // namespace

double CameraSpread(const std::vector<CoverageView>& views, const PanoramaFrame& frame) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = frame.rotation[3 * r + c];
  const Eigen::Vector3d centre(frame.centre[0], frame.centre[1], frame.centre[2]);
  double spread = 0.0;
  for (const CoverageView& v : views) spread = std::max(spread, (R * (v.pose.Center() - centre)).norm());
  return spread;
}

std::string NameRuns(const std::vector<std::string>& names, const std::vector<std::string>& order) {
  std::vector<int> index;
  std::vector<std::string> unknown;
  for (const std::string& n : names) {
    const auto it = std::find(order.begin(), order.end(), n);
    if (it == order.end()) unknown.push_back(n);
    else index.push_back(static_cast<int>(it - order.begin()));
  }
  std::sort(index.begin(), index.end());
  index.erase(std::unique(index.begin(), index.end()), index.end());
  std::vector<std::string> parts;
  for (size_t i = 0; i < index.size();) {
    size_t j = i;
    while (j + 1 < index.size() && index[j + 1] == index[j] + 1) ++j;
    parts.push_back(j == i ? order[index[i]] : order[index[i]] + "-" + order[index[j]]);
    i = j + 1;
  }
  std::sort(unknown.begin(), unknown.end());
  parts.insert(parts.end(), unknown.begin(), unknown.end());
  std::string out;
  for (size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) out += i + 1 == parts.size() ? " and " : ", ";
    out += parts[i];
  }
  return out;
}

namespace {

// Where the cameras were: spread, extent, the pivot the optical axes meet
// at, off-axis distances from it, and whether the camera turned about it,
// walked around the subject or along it.
void MeasureCameraCentres(const std::vector<CoverageView>& views, const PanoramaFrame& frame,
                          const CaptureShapeOptions& options, CaptureShape* s) {
  const int n = static_cast<int>(views.size());
  s->spread = CameraSpread(views, frame);
  std::vector<Eigen::Vector3d> centres, axes;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    centres.push_back(views[i].pose.Center());
    axes.push_back(views[i].pose.R().row(2).transpose());
    mean += centres.back() / n;
    for (int j = 0; j < i; ++j) s->extent = std::max(s->extent, (centres[i] - centres[j]).norm());
  }
  // The pivot: the point nearest (least squares) to every optical axis's
  // line, pulled slightly towards the mean centre so that parallel axes
  // (all looking one way) leave it there.
  const double pull = 1e-3 * n;
  Eigen::Matrix3d A = pull * Eigen::Matrix3d::Identity();
  Eigen::Vector3d b = pull * mean;
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - axes[i] * axes[i].transpose();
    A += across;
    b += across * centres[i];
  }
  const Eigen::Vector3d pivot = A.ldlt().solve(b);
  // Turned about it: the pivot is behind the cameras (on average) and
  // within the cameras' reach of their mean; else the axes meet ahead of
  // them (around a subject) or nowhere near (along it), and the camera
  // centres' distances from their mean are what the walk added.
  double ahead = 0.0, axis_span = 1.0;
  for (int i = 0; i < n; ++i) {
    ahead += (pivot - centres[i]).dot(axes[i]) / n;
    for (int j = 0; j < i; ++j) axis_span = std::min(axis_span, axes[i].dot(axes[j]));
  }
  s->turned = ahead <= 0 && (pivot - mean).norm() <= s->extent;
  std::vector<double> off_axis;
  for (int i = 0; i < n; ++i) {
    if (!s->turned) {
      off_axis.push_back((centres[i] - mean).norm());
      continue;
    }
    const Eigen::Vector3d offset = centres[i] - pivot;
    off_axis.push_back((offset - std::max(0.0, offset.dot(axes[i])) * axes[i]).norm());
  }
  s->off_axis = Quantile(&off_axis, options.off_axis_percentile);
  s->axis_span_deg = std::acos(std::clamp(axis_span, -1.0, 1.0)) * 180.0 / kPi;
  // Axes that meet ahead of the cameras from directions far apart: the
  // camera walked around the subject.
  s->around = !s->turned && ahead > 0 && s->axis_span_deg >= 30.0;
}

// Near depth: a low percentile of the camera-frame depths of every
// observation; with it, whether the camera walked.
void MeasureNearDepth(const geometry::SparseModel& model,
                      const std::vector<const geometry::ModelImage*>& images,
                      const std::vector<CoverageView>& views, const CaptureShapeOptions& options,
                      CaptureShape* s) {
  std::vector<double> depths;
  for (size_t i = 0; i < images.size(); ++i) {
    const Eigen::Matrix3d R = views[i].pose.R();
    for (const geometry::Observation2D& o : images[i]->points2d) {
      if (o.point3d_id == geometry::kInvalidPoint3DId) continue;
      const auto it = model.points.find(o.point3d_id);
      if (it == model.points.end()) continue;
      const double z = (R * it->second.xyz + views[i].pose.translation).z();
      if (z > 0) depths.push_back(z);
    }
  }
  s->near_depth = Quantile(&depths, options.near_percentile);
  if (s->near_depth > 0) {
    s->off_axis_over_near = s->off_axis / s->near_depth;
    s->spread_over_near = s->spread / s->near_depth;
  }
  s->walked = s->near_depth > 0 && s->off_axis_over_near > options.max_off_axis_over_near;
}

// Coverage of the sphere of directions: by all photos, by the median photo,
// and whether they all look one way.
void MeasureCoverage(const std::vector<CoverageView>& views, const CaptureShapeOptions& options,
                     CaptureShape* s) {
  const int n = static_cast<int>(views.size());
  const std::vector<Eigen::Vector3d> dirs = SphereDirections(options.sphere_samples);
  std::vector<uint8_t> seen(dirs.size(), 0);
  std::vector<double> photo_fractions;
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d R = views[i].pose.R();
    int count = 0;
    for (size_t k = 0; k < dirs.size(); ++k) {
      if (!Sees(views[i].camera, R, dirs[k])) continue;
      seen[k] = 1;
      ++count;
    }
    photo_fractions.push_back(static_cast<double>(count) / dirs.size());
  }
  s->sphere_fraction = static_cast<double>(std::count(seen.begin(), seen.end(), 1)) / dirs.size();
  s->photo_sphere_fraction = Quantile(&photo_fractions, 0.5);
  s->narrow = n > 1 && s->sphere_fraction < options.min_sweep * s->photo_sphere_fraction;
}

// Overlap: points shared by each pair of photos, and the groups of linked
// photos (largest first) with the strongest link of each other group to the
// largest.
void GroupLinkedPhotos(const geometry::SparseModel& model,
                       const std::vector<const geometry::ModelImage*>& images,
                       const std::map<int, int>& index_of, const CaptureShapeOptions& options,
                       CaptureShape* s) {
  const int n = static_cast<int>(images.size());
  std::vector<int> shared(static_cast<size_t>(n) * n, 0), points(n, 0);
  std::vector<int> seen_by;
  for (const auto& [id, point] : model.points) {
    seen_by.clear();
    for (const geometry::TrackElement& t : point.track) {
      const auto it = index_of.find(t.image_id);
      if (it != index_of.end()) seen_by.push_back(it->second);
    }
    std::sort(seen_by.begin(), seen_by.end());
    seen_by.erase(std::unique(seen_by.begin(), seen_by.end()), seen_by.end());
    for (size_t a = 0; a < seen_by.size(); ++a) {
      ++points[seen_by[a]];
      for (size_t b = a + 1; b < seen_by.size(); ++b) {
        ++shared[size_t(seen_by[a]) * n + seen_by[b]];
        ++shared[size_t(seen_by[b]) * n + seen_by[a]];
      }
    }
  }
  util::UnionFind sets(n);
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const int k = shared[size_t(i) * n + j];
      if (k >= options.min_link_points && k >= options.min_link_fraction * std::min(points[i], points[j]))
        sets.Union(i, j);
    }
  std::map<int, std::vector<int>> members;
  for (int i = 0; i < n; ++i) members[sets.Find(i)].push_back(i);
  std::vector<std::vector<int>> groups;
  for (auto& [root, m] : members) groups.push_back(m);
  // Largest first; ties: the one with the earliest name (members are in name order).
  std::stable_sort(groups.begin(), groups.end(),
                   [](const auto& a, const auto& b) { return a.size() > b.size(); });
  for (size_t g = 0; g < groups.size(); ++g) {
    std::vector<std::string> names;
    for (int i : groups[g]) names.push_back(images[i]->name);
    s->groups.push_back(names);
    if (g == 0) continue;
    int most = 0;
    for (int i : groups[g])
      for (int j : groups[0]) most = std::max(most, shared[size_t(i) * n + j]);
    s->group_links.push_back(most);
  }
}

}  // namespace

CaptureShape MeasureCaptureShape(const geometry::SparseModel& model, const PanoramaFrame& frame,
                                 const std::vector<std::string>& unregistered, bool metric,
                                 const CaptureShapeOptions& options) {
  if (const Status st = options.Check(); !st.ok()) throw std::invalid_argument("capture shape options: " + st.message());
  CaptureShape s;
  s.metric = metric;
  s.unregistered = unregistered;
  std::sort(s.unregistered.begin(), s.unregistered.end());

  // Registered photos in name order, with their cameras.
  std::vector<const geometry::ModelImage*> images;
  for (const auto& [id, image] : model.images) {
    if (model.cameras.count(image.camera_id)) images.push_back(&image);
  }
  std::sort(images.begin(), images.end(),
            [](const auto* a, const auto* b) { return a->name < b->name; });
  const int n = static_cast<int>(images.size());
  s.num_registered = n;
  s.num_photos = n + static_cast<int>(s.unregistered.size());
  std::vector<std::string> order;
  for (const auto* image : images) order.push_back(image->name);
  order.insert(order.end(), s.unregistered.begin(), s.unregistered.end());
  std::sort(order.begin(), order.end());
  if (n == 0) {
    AddAdvice(order, &s);
    return s;
  }

  std::vector<CoverageView> views;
  std::map<int, int> index_of;  // image_id -> index in `images`.
  for (int i = 0; i < n; ++i) {
    views.push_back({model.cameras.at(images[i]->camera_id).PinholePart(), images[i]->pose});
    index_of[images[i]->image_id] = i;
  }
  MeasureCameraCentres(views, frame, options, &s);
  MeasureNearDepth(model, images, views, options, &s);
  MeasureCoverage(views, options, &s);
  GroupLinkedPhotos(model, images, index_of, options, &s);
  AddAdvice(order, &s);
  return s;
}

CaptureShape MeasureWorkspaceCaptureShape(const std::string& sparse_dir,
                                          const CaptureShapeOptions& options) {
  const fs::path dir(sparse_dir);
  const geometry::SparseModel model = geometry::ReadModel((dir / "sparse").string());
  const PanoramaFrame frame = sfm::ReadPanoramaFrame((dir / "frame.json").string());
  std::vector<std::string> unregistered;
  std::error_code ec;
  // Synthetic captures (capture.json) are in metres, also when the stage
  // read one as a workspace; COLMAP's models of photos are not.
  bool metric = fs::exists(dir / "capture.json", ec);
  const fs::path stage = dir / "stage.json";
  if (fs::exists(stage, ec)) {
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(io::ReadFile(stage.string()));
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(stage.string() + ": not valid JSON (" + e.what() + ")");
    }
    if (j.contains("unregistered") && j["unregistered"].is_array())
      for (const auto& name : j["unregistered"])
        if (name.is_string()) unregistered.push_back(name.get<std::string>());
    if (j.value("input_type", "") == "workspace" && j.contains("input") && j["input"].is_string())
      metric = metric || fs::exists(fs::path(j["input"].get<std::string>()) / "capture.json", ec);
  }
  return MeasureCaptureShape(model, frame, unregistered, metric, options);
}

nlohmann::json CaptureShapeJson(const CaptureShape& s) {
  nlohmann::json groups = nlohmann::json::array();
  for (size_t g = 0; g < s.groups.size(); ++g) {
    nlohmann::json e = {{"photos", s.groups[g]}};
    if (g > 0) e["shared_points_with_largest"] = s.group_links[g - 1];
    groups.push_back(e);
  }
  return {{"photos", s.num_photos},
          {"registered", s.num_registered},
          {"unit", s.metric ? "m" : "model"},
          {"spread", s.spread},
          {"extent", s.extent},
          {"off_axis", s.off_axis},
          {"near_depth", s.near_depth},
          {"spread_over_near", s.spread_over_near},
          {"off_axis_over_near", s.off_axis_over_near},
          {"walked", s.walked},
          {"turned_about_a_point", s.turned},
          {"axis_span_deg", s.axis_span_deg},
          {"moved_around_subject", s.walked && s.around},
          {"sphere_fraction", s.sphere_fraction},
          {"photo_sphere_fraction", s.photo_sphere_fraction},
          {"narrow", s.narrow},
          {"groups", groups},
          {"unregistered", s.unregistered},
          {"warning", s.warning()},
          {"advice", s.advice}};
}

}  // namespace casual3d::pipeline
