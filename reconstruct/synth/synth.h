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
// The same options give the same bytes in every file, whatever the thread count.

#include <cstdint>
#include <string>

#include "format/status.h"
#include "reconstruct/synth/rig.h"

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
  int num_threads = 0;            // 0: all cores.

  // Empty if valid; otherwise one line naming the option and its valid range.
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
};

// Writes the capture folder `dir` (created if missing; existing files of the
// layout are replaced, each atomically). Throws std::runtime_error (io::IoException
// for files) with one line naming the problem; options are checked first.
CaptureSummary GenerateCapture(const SynthOptions& options, const std::string& dir);

}  // namespace casual3d::synth
