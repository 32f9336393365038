#pragma once

// The shape of a capture, measured from its registered cameras and sparse
// points, and advice in plain words when it is not what a 3D photo needs (a
// few dozen photos taken from one spot, turning around, each overlapping its
// neighbours; Hedman et al. 2017, Sec. 3).
//
// Measures (lengths in the model's unit: metres when `metric`):
//   spread      the largest distance of a camera centre from the 3D photo's
//               centre (CameraSpread; the viewing volume of view_volume.h is
//               this, bounded by the near depth).
//   extent      the largest distance between two camera centres: how far the
//               camera travelled.
//   off_axis    a high percentile over the cameras of what the camera moved
//               beyond turning. The pivot is the point nearest to all optical
//               axes (least squares). A phone held at arm's length and turned
//               swings about a pivot behind it (within the cameras' extent of
//               their mean), along its axes: off_axis is the centres'
//               distance from the pivot once the part along each camera's
//               own axis, outwards, is removed (near 0). Otherwise (the axes
//               meet ahead of the cameras: walking around a subject; or they
//               are parallel: walking along it) it is the centres' distance
//               from their mean.
//   near_depth  a low percentile of the camera-frame depths of every
//               observation of a sparse point: the nearest scene the photos
//               saw.
//   sphere      the share of the sphere of directions that at least one photo
//               sees (directions at infinity; Fibonacci samples), and the
//               median photo's share.
//   overlap     per photo, the sparse points it shares with each other photo;
//               photos linked by at least min_link_points and
//               min_link_fraction of the smaller photo's points form groups
//               (connected components); photos outside the largest group are
//               weakly connected, unregistered photos overlap nothing.
//
// Advice: off_axis / near_depth above max_off_axis_over_near is a capture
// that walked: a single-centre 3D photo cannot show views far from its
// centre. Coverage below min_sweep times one photo is a capture that did not
// turn. Weak groups and unregistered photos are named (runs of consecutive
// file names as "a.jpg-d.jpg").

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "format/status.h"
#include "format/equirect.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/pipeline/coverage.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::pipeline {

struct CaptureShapeOptions {
  // Percentile of the observations' camera-frame depths taken as the near
  // depth; [0, 0.5].
  double near_percentile = 0.05;
  // Percentile over the cameras of their off-axis distance; [0.5, 1].
  double off_axis_percentile = 0.9;
  // off_axis / near_depth above this: the camera walked; (0, 10]. An arm's
  // length swing (about 0.3 m, along the axes) adds nothing; 0.15 is a step
  // of 15 cm beside objects 1 m away, where a single centre's views of near
  // objects open gaps well beyond what the back layer fills (view_volume.h
  // bounds the viewing volume at 0.06 of the near depth).
  double max_off_axis_over_near = 0.15;
  // Union of the photos' views below this many times the median photo's
  // view: the photos all look one way; [1, 100].
  double min_sweep = 1.5;
  // A link between two photos: at least this many shared points, [1, 1e6],
  // and this share of the smaller photo's points, [0, 1].
  int min_link_points = 30;
  double min_link_fraction = 0.05;
  // Directions sampled on the sphere for the coverage, [64, 1e6].
  int sphere_samples = 8192;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("near_percentile", o.near_percentile, R::Closed(0, 0.5),
            "Percentile of the observations' camera-frame depths taken as the near depth");
    v.Field("off_axis_percentile", o.off_axis_percentile, R::Closed(0.5, 1),
            "Percentile over the cameras of their off-axis distance");
    v.Field("max_off_axis_over_near", o.max_off_axis_over_near, R::OpenClosed(0, 10),
            "Off-axis distance over near depth above which the camera walked");
    v.Field("min_sweep", o.min_sweep, R::Closed(1, 100),
            "Union of the photos' views over the median photo's view below which they look one way");
    v.Field("min_link_points", o.min_link_points, R::Closed(1, 1e6),
            "Shared points that link two photos");
    v.Field("min_link_fraction", o.min_link_fraction, R::Closed(0, 1),
            "Share of the smaller photo's points that link two photos");
    v.Field("sphere_samples", o.sphere_samples, R::Closed(64, 1e6),
            "Directions sampled on the sphere for the coverage");
  }
  Status Check() const { return util::CheckFields(*this); }  // Names the field and its range.
};

struct CaptureShape {
  int num_photos = 0;      // Registered plus unregistered.
  int num_registered = 0;
  bool metric = false;     // Lengths in metres (else the model's unit).
  double spread = 0.0;
  double extent = 0.0;
  double off_axis = 0.0;
  double near_depth = 0.0;     // 0 without any observation in front of a camera.
  double off_axis_over_near = 0.0;
  double spread_over_near = 0.0;
  double sphere_fraction = 0.0;        // [0, 1].
  double photo_sphere_fraction = 0.0;  // Median photo's, [0, 1].
  // Groups of linked photos (names), the largest first.
  std::vector<std::vector<std::string>> groups;
  // Per group after the first: the most points it shares with the first.
  std::vector<int> group_links;
  std::vector<std::string> unregistered;
  bool walked = false;       // off_axis_over_near > max_off_axis_over_near.
  bool turned = false;       // The camera swung about a pivot behind it.
  double axis_span_deg = 0.0;  // Largest angle between two optical axes.
  bool around = false;       // Not turned, the axes meet ahead, span >= 30 degrees.
  bool narrow = false;       // Union of views < min_sweep x one photo's.
  // Plain-words sentences: what the capture is and what to do. The first
  // one describes the capture; warnings follow.
  std::vector<std::string> advice;
  bool warning() const { return walked || narrow || groups.size() > 1 || !unregistered.empty(); }
};

// The largest distance of a view's camera centre from the frame's centre, in
// the panorama frame (0 without views).
double CameraSpread(const std::vector<CoverageView>& views, const PanoramaFrame& frame);

// Measures `model` (registered photos with their points) whose 3D photo has
// `frame`; `unregistered` are the names of photos that were not placed.
// Throws std::invalid_argument for invalid options.
CaptureShape MeasureCaptureShape(const geometry::SparseModel& model, const PanoramaFrame& frame,
                                 const std::vector<std::string>& unregistered, bool metric,
                                 const CaptureShapeOptions& options = CaptureShapeOptions());

// The same for a sparse stage output (spec/stage-sparse.md: sparse/,
// frame.json, stage.json; a capture.json in it or in the workspace it read
// marks a metric model). Throws
// std::runtime_error naming the file when one is missing or unreadable.
CaptureShape MeasureWorkspaceCaptureShape(const std::string& sparse_dir,
                                          const CaptureShapeOptions& options = CaptureShapeOptions());

// Names as runs of consecutive names of `order`: "a.jpg", "a.jpg-c.jpg",
// "a.jpg, c.jpg and e.jpg-g.jpg".
std::string NameRuns(const std::vector<std::string>& names, const std::vector<std::string>& order);

// report.json's "capture" section: the measures, the groups, the advice.
nlohmann::json CaptureShapeJson(const CaptureShape& shape);

}  // namespace casual3d::pipeline
