#pragma once

// A synthetic capture as a hand-held video clip: the frames a phone records
// while it is swept through the same grid of directions as the photos
// (rig.h), to be encoded into a clip by a video encoder (e.g. FFmpeg) and fed
// to `casual3d reconstruct clip.mp4`. Written by `casual3d synth --video-frames N`:
//   DIR/video/frame_NNNNNN.jpg   the frames in clip order, sRGB JPEG, named as
//                                the video import names picked frames
//                                (sfm/video_import.h VideoFrameName)
//   DIR/video/sparse/            ground-truth COLMAP model (no points) of the
//                                frames and of the photos, in the photos' world
// The path: a second hand-held take of the rig (the same nominal directions,
// its own jitter), so no frame sits exactly at a photo's pose; a Catmull-Rom
// spline through the take's camera centres and, for the orientations, through
// their rotation vectors about the take's mean orientation; frames evenly
// spaced in time, the first and last at the take's first and last pose.
// Exposure drifts smoothly (auto exposure) within the photos' jitter range.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "reconstruct/geometry/camera.h"
#include "reconstruct/geometry/pose.h"
#include "reconstruct/synth/rig.h"
#include "reconstruct/synth/scene.h"

namespace casual3d::synth {

// Name of frame `index` of a clip: "frame_000123.jpg" (as sfm::VideoFrameName).
std::string ClipFrameName(int index);

// `num_frames` (>= 2) poses along a C1 spline through `keys` (>= 2 poses,
// world to camera, all within 90 degrees of their mean orientation), evenly
// spaced in the key parameter: frame f is at key time f * (K - 1) / (N - 1),
// so the first and last frames are the first and last keys. `key_times`, if
// not null, receives each frame's key time.
std::vector<geometry::Pose> ClipPath(const std::vector<geometry::Pose>& keys, int num_frames,
                                     std::vector<double>* key_times = nullptr);

// Options of the clip (filled by SynthOptions, synth.h).
struct ClipOptions {
  int num_frames = 300;                 // >= 2.
  uint64_t seed = 1;                    // The capture's seed.
  double noise_sigma = 1.0;             // Sensor noise, 8-bit code values.
  double exposure_jitter_stops = 0.15;  // Exposure drift within +-this many stops.
  bool moving_object = false;           // Ball displaced by moving_step_m per photo interval.
  double moving_step_m = 0.01;
  int jpeg_quality = 95;
  int edge_samples = 3;
  int num_threads = 0;
};

// How near the clip passes to a photo: its nearest frame by camera centre.
struct NearestFrame {
  std::string photo;
  std::string frame;
  double distance_m = 0;  // Between the camera centres, metres.
  double angle_deg = 0;   // Between the orientations, degrees.
};

struct ClipSummary {
  int num_frames = 0;
  std::vector<NearestFrame> nearest;  // One per photo.
  double seconds = 0;
};

// Renders the clip of `rig_options`' rig around `centre` in `scene` into
// DIR/video (layout above). `photo_rig` and `photo_names` are the photos'
// rig and names, added to the ground-truth model (image ids 1..P; frames
// P+1..P+N) and used for ClipSummary::nearest. Throws on I/O errors.
ClipSummary WriteClip(const ClipOptions& options, const RigOptions& rig_options,
                      const Eigen::Vector3d& centre, const Scene& scene, const Rig& photo_rig,
                      const std::vector<std::string>& photo_names, const std::string& dir);

}  // namespace casual3d::synth
