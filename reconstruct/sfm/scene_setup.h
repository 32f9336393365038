#pragma once

// Scene set-up from a sparse reconstruction (Sec. 4.1 of the paper):
//  - the per-photo depth range that bounds the dense stage's plane sweep, from
//    the sparse points each photo observes (robust percentiles with margins),
//    its near end also bounded by other photos' points inside its view;
//  - the 3D photo's frame (format/equirect.h's PanoramaFrame): the centre of the
//    central panorama, its up direction and, for partial captures, its forward
//    direction;
// and their JSON files in a sparse stage output (spec/stage-sparse.md):
// depth_ranges.json and frame.json.
//
// Units: depths are in the model's length unit, which is metres for metric
// models (synthetic captures) and COLMAP's arbitrary unit for real captures.

#include <map>
#include <string>

#include <Eigen/Core>

#include "format/equirect.h"
#include "format/status.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::sfm {

// ---------------------------------------------------------------------------
// Depth ranges.

struct DepthRangeOptions {
  // Percentiles of the observed points' camera-frame depth (fraction in [0, 1),
  // near < far) taken as the raw near and far bounds; trims outlier points.
  double near_percentile = 0.02;  // Range [0, 0.5).
  double far_percentile = 0.98;   // Range (0.5, 1].
  // The raw bounds are widened by these factors: near *= near_margin,
  // far *= far_margin, so geometry slightly beyond the sparse points is kept.
  double near_margin = 0.8;  // Range (0, 1].
  double far_margin = 1.25;  // Range [1, 100].
  // A photo needs at least this many observed points with positive depth for
  // its own range; otherwise the fallback applies (see ComputeDepthRanges).
  int min_points = 20;  // Range [1, 1e6].
  // Near bounds are clamped to at least this fraction of the far bound, which
  // keeps the inverse-depth sweep finite when a point lies at the lens.
  double min_near_over_far = 1e-3;  // Range (0, 1).
  // A photo's near bound (of an "observed" range) is also at most
  // near_margin times the depth of the k-th nearest model point that at
  // least 3 photos observe and that projects inside the photo (k this many):
  // a near object that other photos' matches found and this photo's missed
  // (at the edge of its view, say) stays inside its sweep. 0 disables.
  int frustum_near_points = 5;  // Range [0, 1000].

  // Names the first field out of range.
  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("near_percentile", o.near_percentile, R::ClosedOpen(0, 0.5), "Percentile of point depths taken as the raw near bound");
    v.Field("far_percentile", o.far_percentile, R::OpenClosed(0.5, 1), "Percentile of point depths taken as the raw far bound");
    v.Field("near_margin", o.near_margin, R::OpenClosed(0, 1), "Near bound factor");
    v.Field("far_margin", o.far_margin, R::Closed(1, 100), "Far bound factor");
    v.Field("min_points", o.min_points, R::Closed(1, 1e6), "Observed points a photo needs for its own range");
    v.Field("min_near_over_far", o.min_near_over_far, R::Open(0, 1), "Near bounds are at least this fraction of the far bound");
    v.Field("frustum_near_points", o.frustum_near_points, R::Closed(0, 1000),
            "Near bound at most near_margin times the depth of this many-th nearest point of 3+ photos inside the view; 0: off");
  }
  Status Check() const { return util::CheckFields(*this); }
};

struct DepthRange {
  std::string name;     // The photo's name in the model.
  double near_m = 0.0;  // Camera-frame depth (along the optical axis), > 0.
  double far_m = 0.0;   // > near_m.
  int num_points = 0;   // Points the range was computed from.
  // How the range was obtained: "observed" (points the photo observes),
  // "frustum" (all model points inside its view, when it observes too few) or
  // "global" (the median of the other photos' ranges, when even that fails).
  std::string source = "observed";
};

// Per registered photo (by image_id), its near and far depth. Throws
// std::invalid_argument if the options are invalid, and std::runtime_error if
// the model has no registered photo or no point in front of any photo.
std::map<int, DepthRange> ComputeDepthRanges(const geometry::SparseModel& model,
                                             const DepthRangeOptions& options = {});

// ---------------------------------------------------------------------------
// Panorama frame.

struct PanoramaFrameOptions {
  // Centre: the mean camera centre, or (robust) the geometric median of the
  // camera centres, which ignores a few stray cameras.
  bool robust_centre = false;
  // Forward direction: the mean of the cameras' horizontal viewing directions
  // when its length (1 = all look the same way, 0 = they look all around) is at
  // least this value (a partial capture); otherwise the capture counts as a full
  // 360 degree capture and forward is the first camera's (lowest image_id)
  // horizontal viewing direction, which is stable from run to run.
  double min_partial_resultant = 0.3;  // Range [0, 1].

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("robust_centre", o.robust_centre, R::Any(), "Centre at the geometric median of the cameras, not their mean");
    v.Field("min_partial_resultant", o.min_partial_resultant, R::Closed(0, 1),
            "Mean viewing direction length from which a capture counts as partial");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// What ComputePanoramaFrame decided, for logs and frame.json.
struct PanoramaFrameInfo {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();   // World coordinates.
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();      // Unit, world coordinates.
  Eigen::Vector3d forward = -Eigen::Vector3d::UnitZ();  // Unit, orthogonal to up.
  double resultant = 0.0;   // Length of the mean horizontal viewing direction.
  bool full_capture = false;  // resultant < min_partial_resultant.
  int num_cameras = 0;
  double rig_radius = 0.0;  // Mean distance of the camera centres from `centre`.
};

// The 3D photo's frame of a sparse model: centre (mean or geometric median of
// the camera centres), up (the normalised mean of the cameras' up vectors, the
// camera -Y axes), forward (see PanoramaFrameOptions), and the rotation from
// world to panorama frame (+X right, +Y up, -Z forward). Throws
// std::invalid_argument for invalid options and std::runtime_error if the model
// has no registered photo or its cameras' up vectors cancel out.
PanoramaFrame ComputePanoramaFrame(const geometry::SparseModel& model,
                                   const PanoramaFrameOptions& options = {},
                                   PanoramaFrameInfo* info = nullptr);

// Eigen views of a PanoramaFrame.
Eigen::Matrix3d FrameRotation(const PanoramaFrame& frame);
Eigen::Vector3d FrameCentre(const PanoramaFrame& frame);
// p_panorama = rotation * (p_world - centre).
Eigen::Vector3d WorldToPanorama(const PanoramaFrame& frame, const Eigen::Vector3d& p_world);

// ---------------------------------------------------------------------------
// Files (spec/stage-sparse.md). Writers write atomically (temporary name, then
// rename) and throw std::runtime_error naming the path on failure. Readers
// throw std::runtime_error naming the path and the field for missing files,
// malformed JSON, unknown major versions or invalid values (non-orthonormal
// rotation, near >= far, ...); unknown fields are ignored.

void WriteDepthRanges(const std::map<int, DepthRange>& ranges, const std::string& path);
std::map<int, DepthRange> ReadDepthRanges(const std::string& path);

// `info` is optional; when given its diagnostics are stored too (readers ignore them).
void WritePanoramaFrame(const PanoramaFrame& frame, const std::string& path,
                        const PanoramaFrameInfo* info = nullptr);
PanoramaFrame ReadPanoramaFrame(const std::string& path);

}  // namespace casual3d::sfm
