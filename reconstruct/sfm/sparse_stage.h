#pragma once

// The sparse stage (Sec. 4.1 of the paper): photos in, calibrated cameras out.
//
// Input: a folder of photos (JPEG, PNG, TIFF, HEIF, with EXIF), a video clip
// (or a folder holding one video: video_import.h picks its frames), or an
// existing COLMAP workspace (DIR/images plus a sparse model in DIR/sparse or
// DIR/sparse/N).
// For photos it imports them at the working resolution (photo_import.h), runs
// Debian's COLMAP on the CPU (feature_extractor; descriptor matching by
// descriptor_matcher.h, then COLMAP's exhaustive or sequential matcher for
// the geometric verification; mapper) and keeps the largest model; for a workspace it takes the
// largest model found. Both then run COLMAP's image_undistorter and set up the
// scene (scene_setup.h).
//
// Output (spec/stage-sparse.md), written to OUT.tmp-XXXXXX and renamed to OUT
// only when complete:
//   OUT/images/            undistorted photos (PINHOLE cameras)
//   OUT/sparse/            COLMAP model of the undistorted cameras, .bin and .txt
//   OUT/frame.json         the 3D photo's frame (PanoramaFrame)
//   OUT/depth_ranges.json  per-photo near/far depth
//   OUT/sparse_log.txt     COLMAP's full output and the stage's notes
//   OUT/stage.json         inputs, options, counts and timings per step

#include <string>
#include <utility>
#include <vector>

#include "format/status.h"
#include "reconstruct/sfm/photo_import.h"
#include "reconstruct/sfm/scene_setup.h"
#include "reconstruct/sfm/video_import.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::sfm {

enum class SparseInputType {
  kAuto,       // A workspace if DIR/images and a model below DIR/sparse exist, else photos.
  kPhotos,     // A folder of photos, or a video.
  kWorkspace,  // A COLMAP workspace.
};

enum class MatcherType {
  kAuto,        // Exhaustive up to exhaustive_max_photos photos, else sequential.
  kExhaustive,  // Every pair: best for small, unordered captures.
  kSequential,  // Neighbours in file-name order: for large, ordered captures.
};

struct SparseStageOptions {
  SparseInputType input_type = SparseInputType::kAuto;
  PhotoImportOptions import;
  VideoFrameOptions video;  // For a video input.
  // COLMAP camera model of the photos: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL,
  // RADIAL or OPENCV. SIMPLE_RADIAL is COLMAP's default for phone photos.
  std::string camera_model = "SIMPLE_RADIAL";
  // One calibration per camera group (device, size, focal) rather than per photo.
  bool shared_camera = true;
  MatcherType matcher = MatcherType::kAuto;
  int exhaustive_max_photos = 60;  // Range [3, 1e5]; kAuto's switch-over.
  int sequential_overlap = 10;     // Range [1, 1000]; neighbours matched by kSequential.
  // SIFT features per photo (COLMAP keeps the coarsest ones when it caps;
  // orientations add about half again). Matching time grows with the square
  // (docs/DECISIONS.md, "Sparse: 2048 features from the photo's own size");
  // raise it for weakly textured scenes.
  int max_features = 2048;  // Range [500, 1e5].
  // First octave of the SIFT pyramid. COLMAP's -1 doubles each photo before
  // detection, for features finer than a pixel, at several times the
  // extraction and matching time (docs/DECISIONS.md, "Sparse: 2048 features
  // from the photo's own size"). -1 for tiny photos or weak texture.
  int sift_first_octave = 0;  // Range [-1, 2].
  // Match descriptors with casual3d's CPU matcher (descriptor_matcher.h: the
  // same criteria, about 9 times faster on 2 cores) and let COLMAP only verify
  // the matches geometrically; false runs COLMAP's own CPU matcher.
  bool native_matching = true;
  // Threads of casual3d's descriptor matching. COLMAP's steps run on one
  // thread, so that the same photos always give the same model.
  int num_threads = 0;             // Range [0, 1024]; 0 = all cores.
  // Smallest triangulation angle of the mapper's initial pair, degrees.
  // COLMAP's 16 suits walk-around captures; a casual capture's photos sit on a
  // ~0.3 m arm (Sec. 4.1) and see the scene from a few degrees apart, so the
  // default pair search fails or starts from a poor pair.
  double init_min_tri_angle_deg = 4.0;  // Range [0.5, 60].
  // Fewer registered photos than this fraction of the input is an error; any
  // unregistered photo is a warning.
  double min_registered_fraction = 0.5;  // Range [0, 1].
  // A photo the mapper registered but that sees fewer 3D points than this
  // is left out as unregistered: nothing ties its pose to the others (the
  // points that registered it were filtered out afterwards), and a pose
  // adrift would move the 3D photo's frame and depth ranges. COLMAP
  // registers a photo from 15 matches at least (Mapper.min_num_matches).
  int min_photo_points = 15;  // Range [0, 1e6]; 0 keeps every registered photo.
  bool overwrite = false;   // Replace an existing OUT (only once the new one is complete).
  bool keep_work = false;   // Keep COLMAP's database and raw models in OUT/work.
  std::string colmap_path;  // Empty: `colmap` on PATH.
  DepthRangeOptions depth_ranges;
  PanoramaFrameOptions frame;

  // Every field of this struct and of the structs nested in it is described
  // here (reconstruct/util/options_fields.h): the checks, the pipeline's cache
  // key and report come from it; sparse_options_test fails when one is missing.
  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("input_type", o.input_type, R::Closed(0, 2), "Input: 0 auto, 1 photos or a video, 2 a COLMAP workspace");
    v.Struct("import", o.import);
    v.Struct("video", o.video);
    v.Field("camera_model", o.camera_model, R::OneOf({"SIMPLE_PINHOLE", "PINHOLE", "SIMPLE_RADIAL", "RADIAL", "OPENCV"}),
            "COLMAP camera model of the photos");
    v.Field("shared_camera", o.shared_camera, R::Any(), "One calibration per camera group rather than per photo");
    v.Field("matcher", o.matcher, R::Closed(0, 2), "Matcher: 0 auto, 1 exhaustive, 2 sequential");
    v.Field("exhaustive_max_photos", o.exhaustive_max_photos, R::Closed(3, 100000), "The automatic matcher's switch-over, photos");
    v.Field("sequential_overlap", o.sequential_overlap, R::Closed(1, 1000), "Neighbours matched by the sequential matcher");
    v.Field("max_features", o.max_features, R::Closed(500, 100000), "SIFT features per photo");
    v.Field("sift_first_octave", o.sift_first_octave, R::Closed(-1, 2), "First octave of the SIFT pyramid (-1: upsampled)");
    v.Field("native_matching", o.native_matching, R::Any(), "Match descriptors with casual3d's matcher, not COLMAP's");
    v.Field("num_threads", o.num_threads, R::Closed(0, 1024), "Threads of the descriptor matching (COLMAP runs on one, for a repeatable model); 0 = all cores",
            util::Keyed::kNo);
    v.Field("init_min_tri_angle_deg", o.init_min_tri_angle_deg, R::Closed(0.5, 60),
            "Smallest triangulation angle of the mapper's initial pair, degrees");
    v.Field("min_registered_fraction", o.min_registered_fraction, R::Closed(0, 1),
            "Fewer registered photos than this fraction is an error");
    v.Field("min_photo_points", o.min_photo_points, R::Closed(0, 1000000),
            "Registered photos seeing fewer 3D points are left out (unregistered); 0 keeps all");
    v.Field("overwrite", o.overwrite, R::Any(), "Replace an existing output folder", util::Keyed::kNo);
    v.Field("keep_work", o.keep_work, R::Any(), "Keep COLMAP's database and raw models in OUT/work");
    v.Field("colmap_path", o.colmap_path, R::Any(), "COLMAP program; empty: colmap on PATH");
    v.Struct("depth_ranges", o.depth_ranges);
    v.Struct("frame", o.frame);
  }
  Status Check() const { return util::CheckFields(*this); }
};

struct SparseStageResult {
  std::string input_type;  // "photos", "video" or "workspace".
  int num_photos = 0;      // Photos given (workspace: images in its model).
  int num_registered = 0;
  std::vector<std::string> unregistered;  // Names.
  std::vector<SkippedPhoto> skipped;      // Files left out by the import.
  VideoFrames video;                      // For a video input.
  int num_points = 0;
  double mean_reprojection_error_px = 0.0;
  std::string matcher;  // "exhaustive", "sequential" or "" (workspace).
  std::vector<std::pair<std::string, double>> timings_s;  // Step, seconds, in order.
  PanoramaFrameInfo frame;
};

// Runs the stage from `input` into `output`. Throws std::invalid_argument for
// bad options and std::runtime_error with one clear line for every failure the
// user can meet (see spec/stage-sparse.md); on failure nothing is left at
// `output` (an existing one is untouched) and COLMAP's log is kept at
// `output` + ".failed-log.txt" when COLMAP had started.
SparseStageResult RunSparseStage(const std::string& input, const std::string& output,
                                 const SparseStageOptions& options);

}  // namespace casual3d::sfm
