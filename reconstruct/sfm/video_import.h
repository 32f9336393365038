#pragma once

// Video input for the sparse stage: `casual3d reconstruct clip.mp4` (or a
// folder holding one video and no photos). Decodes the clip through OpenCV's
// video I/O (FFmpeg), turned upright by the container's rotation metadata, and
// picks the frames that become the capture's photos:
//   1. sharpness of every frame: variance of the Laplacian of a small grey copy;
//      a frame is blurred when it is below blur_ratio times the median of its
//      neighbours (motion blur comes and goes within a few frames);
//   2. motion between consecutive frames: median displacement of corners
//      tracked by pyramidal Lucas-Kanade, summed along the clip;
//   3. the accumulated motion is cut into equal steps (at least min_step of the
//      frame diagonal, at most max_frames frames), and each step keeps its
//      sharpest frame that is not blurred: spread over the motion, not hundreds
//      of near duplicates of a pause.
// Frames carry no focal length: COLMAP starts from its default prior.

#include <string>
#include <vector>

#include "format/status.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::sfm {

struct VideoFrameOptions {
  int max_frames = 40;            // Range [3, 2000]; upper bound on picked frames.
  // Smallest motion between picked frames: median feature displacement as a
  // fraction of the frame diagonal.
  double min_step_fraction = 0.02;  // Range [0, 1].
  double blur_ratio = 0.7;          // Range [0, 1]; 0 keeps every frame.
  int blur_window = 7;              // Range [1, 100]; neighbours on each side.
  int analysis_long_side = 480;     // Range [64, 4096]; pixels of the analysis copy.
  int jpeg_quality = 95;            // Range [50, 100]; quality of the written frames.
  // A video carries no focal length. Without --focal-px, the frames' focal
  // prior is this times their long side (bundle adjustment refines it): 0.8
  // is a phone's main camera filming (about 65 degrees across the long side,
  // a little narrower than its photos). COLMAP's own guess, 1.2 (45 degrees),
  // often finds no initial pair. Range 0 (none: COLMAP's guess) or [0.2, 5].
  double focal_guess = 0.8;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("max_frames", o.max_frames, R::Closed(3, 2000), "Most frames picked from a video");
    v.Field("min_step_fraction", o.min_step_fraction, R::Closed(0, 1),
            "Smallest motion between picked frames, fraction of the frame diagonal");
    v.Field("blur_ratio", o.blur_ratio, R::Closed(0, 1), "Frames less sharp than this times their neighbours' median are skipped; 0 keeps all");
    v.Field("blur_window", o.blur_window, R::Closed(1, 100), "Neighbours on each side for the sharpness test");
    v.Field("analysis_long_side", o.analysis_long_side, R::Closed(64, 4096), "Long side of the analysis copy, pixels");
    v.Field("jpeg_quality", o.jpeg_quality, R::Closed(50, 100), "Quality of the written frames");
    v.Field("focal_guess", o.focal_guess, R::ZeroOr(R::Closed(0.2, 5)),
            "Focal prior of a video's frames without --focal-px, times their long side "
            "(0.8: a phone's main camera); 0 = COLMAP's guess");
  }
  Status Check() const { return util::CheckFields(*this); }
};

struct VideoFrames {
  std::string video;          // Path of the clip.
  int frames_decoded = 0;
  double fps = 0.0;           // From the container; 0 if unknown.
  int width = 0;              // Upright frame size, pixels.
  int height = 0;
  int rotation_deg = 0;       // The container's rotation metadata (applied).
  int blurred = 0;            // Frames judged blurred.
  double motion_diagonals = 0.0;  // Accumulated motion, in frame diagonals.
  std::vector<int> picked;    // Frame indices, increasing.
  double seconds = 0.0;       // Decoding and frame selection.
};

// The name of the picked frame `index` (zero-based, in decoding order) of a
// clip: "frame_000123.jpg". Frames are named by their place in the clip, so
// that a picked frame can be found again (and matched with ground truth
// rendered along the clip, synth/clip.h).
std::string VideoFrameName(int index);

// True for the file names of videos (.mp4, .mov, .m4v, .mkv, .avi, .webm; any case).
bool IsVideoFileName(const std::string& name);

// The video `input` stands for: the file itself if it is named as a video, or
// the one video of a folder that holds no photos; empty for a folder of photos
// (or a workspace). Throws std::runtime_error for a folder with several videos
// and no photos.
std::string VideoOf(const std::string& input);

// Decodes `video`, picks frames and writes them to `output_dir` (must exist)
// named by their index in the clip (VideoFrameName). Throws std::runtime_error with one clear line if
// the file cannot be decoded or yields fewer than 3 frames.
VideoFrames ExtractVideoFrames(const std::string& video, const std::string& output_dir,
                               const VideoFrameOptions& options);

// Picks frames from per-frame sharpness and motion to the next frame (both of
// size n; motion.back() is unused) as ExtractVideoFrames does; `blurred`
// receives the number of blurred frames. `min_step` is in the units of motion.
std::vector<int> PickFrames(const std::vector<double>& sharpness, const std::vector<double>& motion,
                            double min_step, const VideoFrameOptions& options, int* blurred);

}  // namespace casual3d::sfm
