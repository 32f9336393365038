#pragma once

// Virtual rephotography of 3D photos (paper Sec. 6.3): every evaluated photo
// of a capture is re-rendered from the 3D photo at the photo's exact pose
// (reconstruct/render/photo_renderer.h), at about `width` pixels wide, and
// compared with the photo (rephoto_metrics.h). On synthetic captures the
// rendered depth is also compared with the ground-truth depth maps.
//
// Inputs:
//   capture      a photo folder, a capture folder (DIR/images, DIR/sparse,
//                DIR/depth for synthetic captures) or a COLMAP workspace.
//   3D photo     the output folder of `casual3d reconstruct` (OUT/master.exr,
//                OUT/report.json, OUT/work/sparse), a panorama-stage folder
//                holding master.exr, a master .exr file, a package folder
//                (manifest.json; OUT/web) or a single-file package (.c3d).
// Poses: the 3D photo's own sparse model (ROOT/work/sparse/sparse, ROOT being
// the 3D photo's output folder) when it exists, else the capture's
// (CAPTURE/sparse, CAPTURE/sparse/0). Photos are matched by file name; the
// reference image of a photo is the undistorted copy next to the model that
// gave its pose (SPARSE/images/<name>), else CAPTURE/images/<name>, else
// CAPTURE/<name>; it must have the camera's size.
//
// With EvaluateOptions::reference_poses, the evaluated photos' poses and
// cameras come from that reference model instead, mapped into the 3D
// photo's world by aligning the 3D photo's model to it over the photos both
// hold (reference_alignment.h): for photos the 3D photo's model lacks, such
// as the photos held out of a 3D photo made from a video's frames.
//
// Held-out views: ROOT/report.json may list "holdout" (names of photos that
// were registered but not used to build the 3D photo); by default exactly
// those are evaluated. Without such a list every registered photo is.
//
// What a viewer sees (EvaluateOptions::viewer_views, on by default): the 3D
// photo's mesh from 17 viewer cameras over its viewing volume, with tears and
// stretched fill (viewer_views.h); it needs the 3D photo only.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "format/status.h"
#include "format/image.h"
#include "reconstruct/eval/reference_alignment.h"
#include "reconstruct/eval/rephoto_metrics.h"
#include "reconstruct/eval/viewer_views.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::eval {

struct EvaluateOptions {
  // Width of the rephotographs, pixels (height keeps the aspect ratio); the
  // camera is scaled to it. Sec. 6.3: about 900. [16, 8192]; 0 = the photos' size.
  int width = 900;
  // Photos to evaluate, by file name or by zero-based index in the sorted list
  // of the model's image names. Empty = the 3D photo's held-out photos if it
  // lists any, else every registered photo.
  std::vector<std::string> photos;
  // When > 0 and `photos` is empty: evaluate the photos with index 0, n, 2n,
  // ... (the LLFF held-out protocol uses 8). [0, 1000].
  int holdout_every = 0;
  RephotoMetricOptions metrics;
  // Keep the per-photo images (render, error map) for the HTML report.
  bool keep_images = true;
  // Relative depth error threshold of "within" in the ground-truth comparison
  // (0.03 = 3%); (0, 1].
  double depth_tolerance = 0.03;
  int num_threads = 0;  // Rendering threads; 0 = all cores.
  // What a viewer sees (viewer_views.h): tears and stretched fill from 17
  // views over the viewing volume. Needs the 3D photo only.
  bool viewer_views = true;
  ViewerViewsOptions viewer;
  // Draw the 3D photo's backdrop (format/backdrop.h) with its mesh in the
  // viewer views, as the viewer does from inside the viewing volume; false:
  // the mesh alone. The rephotographs always render the mesh alone
  // (spec/mesh.md's, as exported): photos' poses can lie outside the volume,
  // where the backdrop, made for eyes inside it, can hide what lies behind a
  // near object.
  bool backdrop = true;
  // Renderings made elsewhere (external_renders.h): when not empty, each
  // evaluated photo's rendering is read from this folder instead of rendered
  // here (no mesh is built: mesh_triangles stays 0), and the viewer views
  // are skipped (they are this program's renders).
  // Needs cameras without lens distortion (the undistorted workspace).
  std::string rendered_dir;
  // A COLMAP model folder (or a folder with sparse/ or sparse/0) holding the
  // evaluated photos and at least 3 of the 3D photo's own photos (or video
  // frames), by file name: when not empty, the evaluated photos' poses and
  // cameras come from it, mapped into the 3D photo's world
  // (reference_alignment.h), and `photos` and `holdout_every` name or index
  // its photos. Ground-truth depth is compared after the alignment's scale,
  // so the reference must be in the capture's units (its ground truth).
  std::string reference_poses;

  // `photos`, a list, is not described (options_fields.h describes single
  // values); any list is valid.
  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("width", o.width, R::ZeroOr(R::Closed(16, 8192)),
            "Width of the rephotographs in pixels (the camera is scaled); 0 = photo size");
    v.Field("holdout_every", o.holdout_every, R::Closed(0, 1000),
            "Evaluate photos 0, N, 2N, ... (LLFF protocol: 8) when --photos is not given");
    v.Struct("metrics", o.metrics);
    v.Field("keep_images", o.keep_images, R::Any(),
            "Keep the per-photo images (render, error map) for the HTML report");
    v.Field("depth_tolerance", o.depth_tolerance, R::OpenClosed(0, 1),
            "Relative depth error threshold of \"within\" in the ground-truth comparison");
    v.Field("num_threads", o.num_threads, R::Closed(0, 256), "Worker threads; 0 = all cores",
            util::Keyed::kNo);
    v.Field("viewer_views", o.viewer_views, R::Any(),
            "Measure what a viewer sees (tears and stretched fill from 17 views)");
    v.Struct("viewer", o.viewer);
    v.Field("backdrop", o.backdrop, R::Any(),
            "Draw the 3D photo's backdrop with its mesh in the viewer views");
    v.Field("rendered_dir", o.rendered_dir, R::Any(),
            "Score renderings made elsewhere instead of rendering here: one PNG per photo "
            "(<photo stem>.png, RGBA, alpha 0 = nothing drawn) from the cameras of "
            "--write-cameras");
    v.Field("reference_poses", o.reference_poses, R::Any(),
            "Take the evaluated photos' poses from this COLMAP model (e.g. a synthetic "
            "capture's ground truth), aligned to the 3D photo's model by the photos or video "
            "frames both hold (at least 3, by file name): for photos the 3D photo's model lacks");
  }
  Status Check() const { return util::CheckFields(*this); }  // Names the field and its range.
};

// Depth of the rephotograph against a synthetic capture's ground truth
// (CAPTURE/depth/<stem>.exr, camera-frame z): over pixels that are covered
// and have a finite ground-truth depth. When the 3D photo was reconstructed
// with its own camera model (arbitrary scale), its depth is first scaled by
// the ratio of the spreads of the camera centres in CAPTURE/sparse and in
// that model (PhotoModelEvaluation::depth_scale).
struct DepthComparison {
  bool available = false;
  int64_t pixels = 0;
  double median_relative_error = 0.0;  // median of |z - z_true| / z_true.
  double within_tolerance = 0.0;       // Fraction with relative error <= depth_tolerance.
  // Median of z / z_true: near 1 when the errors are noise around the truth,
  // away from 1 when the whole 3D photo is too near or too far (a scale error).
  double median_ratio = 0.0;
};

struct PhotoEvaluation {
  std::string name;
  int index = 0;          // Index in the sorted list of the model's image names.
  bool held_out = false;  // Listed as held out by the 3D photo.
  RephotoMetrics metrics;
  DepthComparison depth;
  double seconds_render = 0.0;
  // The pinhole view of the photo at the evaluated size (panorama frame), and
  // whether its camera has lens distortion that the view leaves out.
  render::PinholeView view;
  bool has_distortion = false;
  // When EvaluateOptions::keep_images: the photo as compared, the rendering
  // and the per-pixel error (rephoto_metrics.h; -1 uncovered).
  Image8 photo, render;
  ImageF error_map;
};

struct PhotoModelEvaluation {
  std::string label;       // The 3D photo's path as given (or a caller's name for it).
  std::string source;      // What was read: "master.exr" path or package path.
  std::string poses_from;  // The sparse model folder used.
  // With EvaluateOptions::reference_poses: how the 3D photo's model was
  // aligned to the reference giving the poses.
  std::optional<ReferenceAlignment> reference_alignment;
  int pano_width = 0, pano_height = 0;
  size_t mesh_triangles = 0;      // spec/mesh.md's mesh.
  size_t backdrop_triangles = 0;  // The backdrop drawn with it in the viewer views.
  uint64_t package_bytes = 0;  // Of the package next to it (OUT/photo.c3d) or the one read, if any.
  std::vector<PhotoEvaluation> photos;
  // Timings per stage read from ROOT/report.json or panorama.json (seconds).
  std::vector<std::pair<std::string, double>> stage_seconds;
  std::vector<std::string> holdout;  // Held-out names listed by the 3D photo.
  // Means over the evaluated photos.
  double mean_error = 0, mean_completeness = 0, mean_psnr_db = 0, mean_ssim = 0;
  double mean_psnr_filled_db = 0, mean_ssim_filled = 0;  // Whole frame, holes filled.
  double mean_depth_median_rel = 0, mean_depth_within = 0;
  bool has_depth = false;
  // Factor applied to the rendered depth before the ground-truth comparison:
  // the 3D photo's model units to the capture's (camera-centre spread ratio
  // when the poses come from the 3D photo's own model), else 1.
  double depth_scale = 1.0;
  // Clip planes of the rephotography (RenderOptions::near_m, far_m).
  double near_m = 0.0, far_m = 0.0;
  std::vector<int64_t> error_histogram;  // Sum over photos.
  int64_t total_pixels = 0;              // Sum of photo sizes.
  // With EvaluateOptions::viewer_views: the viewer-side measure.
  std::optional<ViewerViewsEvaluation> viewer;
};

// Evaluates one 3D photo on `capture_dir`. Throws std::invalid_argument for
// bad options and std::runtime_error with one line naming the input for
// unreadable or inconsistent inputs (no poses, an unknown photo name, a photo
// whose size differs from its camera).
PhotoModelEvaluation EvaluatePhoto3d(const std::string& capture_dir,
                                     const std::string& photo3d_path,
                                     const EvaluateOptions& options);

// Resolves `requested` (names or decimal indices into `names`, sorted) and
// the held-out rule into the list of indices to evaluate, in increasing order
// without duplicates: `requested` if not empty, else indices 0, every, 2 every,
// ... if every > 0, else the names in `holdout` that are in `names`, else all.
// Throws std::runtime_error naming an unknown name or an index out of range.
std::vector<int> SelectPhotos(const std::vector<std::string>& names,
                              const std::vector<std::string>& requested, int every,
                              const std::vector<std::string>& holdout);

}  // namespace casual3d::eval
