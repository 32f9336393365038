#include "reconstruct/sfm/video_import.h"

#include <dirent.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <sys/stat.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <opencv2/videoio.hpp>

#include "reconstruct/io/cv_bridge.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/sfm/photo_import.h"

namespace casual3d::sfm {
namespace {

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

cv::VideoCapture Open(const std::string& video) {
  cv::VideoCapture capture(video, cv::CAP_FFMPEG);
  if (!capture.isOpened()) {
    throw std::runtime_error(video + ": cannot decode the video (not a video file, or no FFmpeg "
                             "decoder for it); give a folder of photos or an MP4/MOV clip");
  }
  // Frames upright as the container's rotation metadata says (phones record
  // portrait clips as rotated landscape).
  capture.set(cv::CAP_PROP_ORIENTATION_AUTO, 1);
  return capture;
}

// Grey copy with the long side at most `long_side` pixels.
cv::Mat AnalysisCopy(const cv::Mat& frame, int long_side) {
  cv::Mat grey;
  cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  const double scale = static_cast<double>(long_side) / std::max(frame.cols, frame.rows);
  if (scale < 1.0) cv::resize(grey, grey, cv::Size(), scale, scale, cv::INTER_AREA);
  return grey;
}

double Sharpness(const cv::Mat& grey) {
  cv::Mat laplacian;
  cv::Laplacian(grey, laplacian, CV_64F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(laplacian, mean, stddev);
  return stddev[0] * stddev[0];
}

// Median displacement of corners tracked from `a` to `b`, pixels; the image
// diagonal when too few corners track (a cut, or no texture).
double Motion(const cv::Mat& a, const cv::Mat& b) {
  std::vector<cv::Point2f> corners, tracked;
  cv::goodFeaturesToTrack(a, corners, 300, 0.01, 6);
  const double diagonal = std::hypot(a.cols, a.rows);
  if (corners.size() < 10) return diagonal;
  std::vector<uchar> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(a, b, corners, tracked, status, error);
  std::vector<double> moved;
  for (size_t i = 0; i < corners.size(); ++i) {
    if (status[i]) moved.push_back(std::hypot(tracked[i].x - corners[i].x, tracked[i].y - corners[i].y));
  }
  if (moved.size() < 10) return diagonal;
  std::nth_element(moved.begin(), moved.begin() + moved.size() / 2, moved.end());
  return moved[moved.size() / 2];
}

}  // namespace

std::string VideoFrameName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%06d.jpg", index);
  return name;
}

bool IsVideoFileName(const std::string& name) {
  const std::string l = Lower(name);
  if (name.empty() || name[0] == '.') return false;
  for (const char* ext : {".mp4", ".mov", ".m4v", ".mkv", ".avi", ".webm"}) {
    const std::string e = ext;
    if (l.size() > e.size() && l.compare(l.size() - e.size(), e.size(), e) == 0) return true;
  }
  return false;
}

std::string VideoOf(const std::string& input) {
  struct stat st;
  if (::stat(input.c_str(), &st) != 0) return "";
  if (S_ISREG(st.st_mode)) return IsVideoFileName(input) ? input : "";
  if (!S_ISDIR(st.st_mode)) return "";
  DIR* dir = ::opendir(input.c_str());
  if (dir == nullptr) return "";
  std::vector<std::string> videos;
  bool photos = false;
  while (dirent* e = ::readdir(dir)) {
    const std::string name = e->d_name;
    if (IsPhotoFileName(name)) photos = true;
    if (IsVideoFileName(name)) videos.push_back(name);
  }
  ::closedir(dir);
  if (photos || videos.empty() || ::stat((input + "/images").c_str(), &st) == 0) return "";
  std::sort(videos.begin(), videos.end());
  if (videos.size() > 1) {
    throw std::runtime_error(input + ": holds " + std::to_string(videos.size()) + " videos (" +
                             videos[0] + ", " + videos[1] +
                             (videos.size() > 2 ? ", ..." : "") +
                             ") and no photos; give one video, or a folder with one");
  }
  return input + "/" + videos[0];
}

std::vector<int> PickFrames(const std::vector<double>& sharpness, const std::vector<double>& motion,
                            double min_step, const VideoFrameOptions& options, int* blurred) {
  const int n = static_cast<int>(sharpness.size());
  std::vector<bool> sharp(n, true);
  int num_blurred = 0;
  for (int i = 0; i < n; ++i) {
    std::vector<double> around;
    for (int j = std::max(0, i - options.blur_window); j <= std::min(n - 1, i + options.blur_window); ++j)
      around.push_back(sharpness[j]);
    std::nth_element(around.begin(), around.begin() + around.size() / 2, around.end());
    sharp[i] = sharpness[i] >= options.blur_ratio * around[around.size() / 2];
    num_blurred += sharp[i] ? 0 : 1;
  }
  if (blurred) *blurred = num_blurred;
  if (n == 0) return {};
  std::vector<double> along(n, 0.0);  // Motion accumulated up to each frame.
  for (int i = 1; i < n; ++i) along[i] = along[i - 1] + motion[i - 1];
  const double total = along.back();
  int count = options.max_frames;
  if (min_step > 0) count = std::min<double>(count, std::floor(total / min_step) + 1);
  count = std::max(1, std::min(count, n));
  const double step = count > 1 ? total / (count - 1) : total + 1;
  std::vector<int> picked;
  int first = 0;  // Frames before `first` belong to earlier steps.
  for (int k = 0; k < count; ++k) {
    // Step k holds the frames whose accumulated motion is within half a step of k steps.
    const double lo = (k - 0.5) * step, hi = (k + 0.5) * step;
    int best = -1;
    for (int i = first; i < n && along[i] < hi; ++i) {
      if (along[i] < lo) continue;
      const bool better = best < 0 || (sharp[i] && !sharp[best]) ||
                          (sharp[i] == sharp[best] && sharpness[i] > sharpness[best]);
      if (better) best = i;
      first = i + 1;
    }
    if (best >= 0) picked.push_back(best);
  }
  return picked;
}

VideoFrames ExtractVideoFrames(const std::string& video, const std::string& output_dir,
                               const VideoFrameOptions& options) {
  const Status status = options.Check();
  if (!status.ok()) throw std::invalid_argument("video frame options: " + status.message());
  const auto start = std::chrono::steady_clock::now();
  VideoFrames result;
  result.video = video;
  std::vector<double> sharpness, motion;
  double diagonal = 0.0;
  {
    cv::VideoCapture capture = Open(video);
    result.fps = capture.get(cv::CAP_PROP_FPS);
    result.rotation_deg = static_cast<int>(capture.get(cv::CAP_PROP_ORIENTATION_META));
    cv::Mat frame, previous;
    while (capture.read(frame) && !frame.empty()) {
      if (result.frames_decoded == 0) {
        result.width = frame.cols;
        result.height = frame.rows;
      }
      cv::Mat grey = AnalysisCopy(frame, options.analysis_long_side);
      diagonal = std::hypot(grey.cols, grey.rows);
      sharpness.push_back(Sharpness(grey));
      if (!previous.empty()) motion.push_back(Motion(previous, grey));
      previous = grey;
      ++result.frames_decoded;
    }
  }
  motion.push_back(0.0);
  if (result.frames_decoded < 3) {
    throw std::runtime_error(video + ": decoded " + std::to_string(result.frames_decoded) +
                             " frames; a 3D photo needs a clip of a few seconds (at least 3 frames)");
  }
  for (int i = 0; i + 1 < result.frames_decoded; ++i) result.motion_diagonals += motion[i] / diagonal;
  result.picked = PickFrames(sharpness, motion, options.min_step_fraction * diagonal, options,
                             &result.blurred);
  if (result.picked.size() < 3) {
    char moved[32];
    std::snprintf(moved, sizeof(moved), "%.2f", result.motion_diagonals);
    throw std::runtime_error(video + ": the view moved by " + moved +
                             " frame diagonals over the clip, enough for " +
                             std::to_string(result.picked.size()) +
                             " distinct frames; a 3D photo needs at least 3: turn slowly "
                             "around while filming");
  }

  // Second pass: write the picked frames at full size.
  cv::VideoCapture capture = Open(video);
  cv::Mat frame;
  size_t next = 0;
  io::JpegOptions jpeg;
  jpeg.quality = options.jpeg_quality;
  for (int i = 0; next < result.picked.size() && capture.read(frame) && !frame.empty(); ++i) {
    if (i != result.picked[next]) continue;
    Image8 rgb(frame.cols, frame.rows, 3);
    cv::Mat dst = io::ToMat(rgb);
    cv::cvtColor(frame, dst, cv::COLOR_BGR2RGB);
    io::WriteJpeg(output_dir + "/" + VideoFrameName(i), rgb, jpeg);
    ++next;
  }
  if (next < result.picked.size()) {
    throw std::runtime_error(video + ": the second decoding pass ended at frame " +
                             std::to_string(result.picked[next]) + " of " +
                             std::to_string(result.frames_decoded));
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace casual3d::sfm
