#pragma once

// `casual3d synth`: renders a synthetic capture of the built-in scene
// (default_scene.h) with a capture rig (rig.h) and writes a capture folder with
// its ground truth. The layout is specified in spec/capture-folder.md:
//   DIR/images/NNNN.jpg        photos, sRGB JPEG
//   DIR/sparse/{cameras,images,points3D}.{txt,bin}  ground-truth COLMAP model
//   DIR/depth/NNNN.exr         per-photo depth: channel Z, metres along the optical axis, +inf sky
//   DIR/ground_truth/panorama.exr  first/second surfaces from the rig centre (ground_truth_panorama.h)
//   DIR/ground_truth/master.exr    the same as a two-layer master file (ground_truth_two_layer.h)
//   DIR/capture.json           rig, seed, options, panorama frame, scene facts
//   DIR/video/                 with video_frames > 0: the capture as a video
//                              clip's frames and their ground truth (clip.h)
// The same options give the same bytes in every file, whatever the thread count.

#include <cstdint>
#include <string>

#include "format/status.h"
#include "reconstruct/synth/rig.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::synth {

struct SynthOptions {
  RigKind rig = RigKind::kPartial;
  int width = 0;                  // Photo width, pixels; 0: the rig's default (1152).
  int height = 0;                 // Photo height, pixels; 0: width * 3 / 4.
  int num_photos = 0;             // 0: the rig's default (partial 16, sphere 50); else 2..1000.
  double noise_sigma = 1.0;       // Sensor noise, standard deviation in 8-bit code values, [0, 50].
  double exposure_jitter_stops = 0.15;  // Per-photo exposure uniform in +-this many stops, [0, 3].
  bool moving_object = false;     // Move the blue ball between photos.
  double moving_step_m = 0.01;    // Ball displacement per photo along +X when moving, metres, [0, 0.2].
  uint64_t seed = 1;              // Textures, jitter, noise, exposure.
  int panorama_width = 2048;      // Ground-truth panorama width (height = width / 2), 16..16384, even.
  int jpeg_quality = 95;          // 1..100.
  int edge_samples = 3;           // Anti-aliasing rays per axis at edge pixels, 1..8.
  int sparse_step_px = 24;        // Grid spacing of sampled 3D points in each photo, pixels.
  bool write_master = true;       // Also write ground_truth/master.exr.
  // Also render the capture as a hand-held video clip of this many frames
  // (DIR/video, clip.h; 300 = 10 s at 30 fps); 0: none, else 2..100000.
  int video_frames = 0;
  int num_threads = 0;            // 0: all cores.

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("rig", o.rig, R::Closed(0, 2), "Capture rig: partial, sphere or walk-around");
    v.Field("width", o.width, R::ZeroOr(R::Closed(16, 16384)),
            "Photo width in pixels; 0 = the rig's default (1152)");
    v.Field("height", o.height, R::ZeroOr(R::Closed(16, 16384)),
            "Photo height in pixels; 0 = width * 3 / 4");
    v.Field("num_photos", o.num_photos, R::ZeroOr(R::Closed(2, 1000)),
            "Number of photos; 0 = the rig's default (partial 16, sphere 50, walk-around 12)");
    v.Field("noise_sigma", o.noise_sigma, R::Closed(0, 50), "Sensor noise sigma, 8-bit code values");
    v.Field("exposure_jitter_stops", o.exposure_jitter_stops, R::Closed(0, 3),
            "Per-photo exposure jitter, +- stops");
    v.Field("moving_object", o.moving_object, R::Any(), "Move the blue ball between photos");
    v.Field("moving_step_m", o.moving_step_m, R::Closed(0, 0.2),
            "Ball displacement per photo when moving, metres");
    v.Field("seed", o.seed, R::Any(), "Seed (textures, jitter, noise)");
    v.Field("panorama_width", o.panorama_width, R::Closed(16, 16384),
            "Ground-truth panorama width (height = width / 2)");
    v.Require(o.panorama_width % 2 == 0, "panorama_width", "must be even (height = width / 2)");
    v.Field("jpeg_quality", o.jpeg_quality, R::Closed(1, 100), "JPEG quality");
    v.Field("edge_samples", o.edge_samples, R::Closed(1, 8),
            "Anti-aliasing rays per axis at edge pixels");
    v.Field("sparse_step_px", o.sparse_step_px, R::Closed(2, 4096),
            "Grid spacing of sampled 3D points in each photo, pixels");
    v.Field("write_master", o.write_master, R::Any(), "Also write ground_truth/master.exr");
    v.Field("video_frames", o.video_frames, R::ZeroOr(R::Closed(2, 100000)),
            "Also render the capture as a hand-held video clip of this many frames "
            "(DIR/video/frame_NNNNNN.jpg and ground truth DIR/video/sparse; 300 = 10 s at 30 fps); "
            "0 = none");
    v.Field("num_threads", o.num_threads, R::AtLeast(0), "Worker threads (0: all cores)",
            util::Keyed::kNo);
  }
  // The described ranges, then the rig these options resolve to (rig.h).
  Status Check() const;  // Names the field and its range.
  // The rig these options describe (defaults filled in).
  RigOptions ResolvedRig() const;
};

struct CaptureSummary {
  int num_photos = 0;
  int width = 0;
  int height = 0;
  size_t num_points = 0;
  double mean_track_length = 0;
  int panorama_width = 0;
  int panorama_height = 0;
  double depth_min_m = 0;  // Nearest finite depth seen by any photo or the panorama.
  double depth_max_m = 0;  // Farthest finite depth.
  double seconds_photos = 0;
  double seconds_panorama = 0;
  double seconds_total = 0;
  bool wrote_master = false;
  int video_frames = 0;        // Frames of the clip written to DIR/video.
  double seconds_video = 0;
  // The clip's nearest frame to each photo (clip.h), when video_frames > 0.
  double video_max_distance_m = 0;   // Largest over the photos of the nearest frame's distance.
  double video_min_distance_m = 0;   // Smallest of them.
};

// Writes the capture folder `dir` (created if missing; existing files of the
// layout are replaced, each atomically). Throws std::runtime_error (io::IoException
// for files) with one line naming the problem; options are checked first.
CaptureSummary GenerateCapture(const SynthOptions& options, const std::string& dir);

}  // namespace casual3d::synth
