#include "reconstruct/sfm/sparse_stage.h"

#include <stdlib.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/sfm/colmap_database.h"
#include "reconstruct/sfm/colmap_runner.h"
#include "reconstruct/sfm/descriptor_matcher.h"
#include "reconstruct/sfm/untied_photos.h"
#include "reconstruct/util/log.h"

namespace casual3d::sfm {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

std::string FormatNumber(double v) {
  std::ostringstream ss;
  ss.precision(10);
  ss << v;
  return ss.str();
}

// COLMAP's --ImageReader.camera_params for `model` with focal f and the
// principal point at the image centre; distortion starts at zero.
std::string CameraParams(const std::string& model, double f, int width, int height) {
  const std::string fs_ = FormatNumber(f);
  const std::string cx = FormatNumber(width / 2.0), cy = FormatNumber(height / 2.0);
  if (model == "SIMPLE_PINHOLE") return fs_ + "," + cx + "," + cy;
  if (model == "PINHOLE") return fs_ + "," + fs_ + "," + cx + "," + cy;
  if (model == "SIMPLE_RADIAL") return fs_ + "," + cx + "," + cy + ",0";
  if (model == "RADIAL") return fs_ + "," + cx + "," + cy + ",0,0";
  return fs_ + "," + fs_ + "," + cx + "," + cy + ",0,0,0,0";  // OPENCV.
}

bool HasModelFiles(const fs::path& dir) {
  return (fs::exists(dir / "cameras.bin") && fs::exists(dir / "images.bin") &&
          fs::exists(dir / "points3D.bin")) ||
         (fs::exists(dir / "cameras.txt") && fs::exists(dir / "images.txt") &&
          fs::exists(dir / "points3D.txt"));
}

// Model folders below a workspace: DIR/sparse itself or DIR/sparse/<N>.
std::vector<fs::path> WorkspaceModels(const fs::path& input) {
  std::vector<fs::path> models;
  const fs::path sparse = input / "sparse";
  std::error_code ec;
  if (!fs::is_directory(sparse, ec)) return models;
  if (HasModelFiles(sparse)) models.push_back(sparse);
  for (const auto& entry : fs::directory_iterator(sparse, ec)) {
    if (entry.is_directory() && HasModelFiles(entry.path())) models.push_back(entry.path());
  }
  std::sort(models.begin(), models.end());
  return models;
}

// The model with the most registered images (then points) among `dirs`.
std::pair<fs::path, geometry::SparseModel> LargestModel(const std::vector<fs::path>& dirs) {
  fs::path best_dir;
  geometry::SparseModel best;
  bool have = false;
  for (const auto& dir : dirs) {
    geometry::SparseModel model = geometry::ReadModel(dir.string());
    if (!have || model.images.size() > best.images.size() ||
        (model.images.size() == best.images.size() && model.points.size() > best.points.size())) {
      best = std::move(model);
      best_dir = dir;
      have = true;
    }
  }
  return {best_dir, std::move(best)};
}

std::string JoinNames(const std::vector<std::string>& names, size_t max_names) {
  std::string out;
  for (size_t i = 0; i < names.size() && i < max_names; ++i) out += (i ? ", " : "") + names[i];
  if (names.size() > max_names) out += ", ... (" + std::to_string(names.size()) + " in all)";
  return out;
}

std::string LastLines(const std::string& text) {
  std::string s = text;
  while (!s.empty() && s.back() == '\n') s.pop_back();
  const size_t pos = s.rfind('\n');
  return pos == std::string::npos ? s : s.substr(pos + 1);
}

// `focal_unknown`: some photos had no focal length (no EXIF, no --focal-px),
// which COLMAP's default guess (1.2 times the long side, a 45-degree view)
// often fails to start from; a video never carries one. `focal_guess`: the
// video's frames started from this guess (VideoFrameOptions::focal_guess,
// times the long side), 0 if none.
std::string NothingRegisteredMessage(int num_photos, const std::string& input_type = "photos",
                                     bool focal_unknown = false, double focal_guess = 0.0) {
  const bool video = input_type == "video";
  const std::string what = std::to_string(num_photos) + (video ? " frames" : " photos");
  if (focal_unknown || (video && focal_guess > 0)) {
    return "COLMAP registered none of the " + what + " (no initial pair found); " +
           (video ? "a video carries no focal length" +
                        (focal_guess > 0 ? " (tried " + FormatNumber(focal_guess) +
                                               " times the long side)"
                                         : std::string())
                  : "the photos carry no focal length (EXIF)") +
           ": give the camera's with --focal-px (pixels at the " + (video ? "video's" : "photos'") +
           " size; about 0.8 times the long side for a phone's main camera)" +
           (video ? "" : ", or take more photos with more overlap of a textured scene");
  }
  return "COLMAP registered none of the " + what +
         " (no initial pair found); take more photos with more overlap (each scene "
         "point in 3 or more photos) of a textured scene, and move the camera between shots";
}

// The temporary output folder and its clean-up on failure.
class StagingDir {
 public:
  StagingDir(const fs::path& output) : output_(output) {
    std::string pattern = output.string() + ".tmp-XXXXXX";
    std::vector<char> buf(pattern.begin(), pattern.end());
    buf.push_back('\0');
    if (::mkdtemp(buf.data()) == nullptr) {
      throw std::runtime_error(output.string() + ": cannot create the output folder here (" +
                               std::strerror(errno) +
                               "); choose a writable location with -o");
    }
    path_ = buf.data();
  }
  ~StagingDir() {
    if (committed_) return;
    std::error_code ec;
    if (fs::exists(path_ / "sparse_log.txt", ec)) {
      const fs::path kept = output_.string() + ".failed-log.txt";
      fs::rename(path_ / "sparse_log.txt", kept, ec);
    }
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

  // Moves the staging folder to `output`, replacing an existing one only now.
  void Commit(bool overwrite) {
    std::error_code ec;
    if (fs::exists(output_, ec) && !overwrite) {
      throw std::runtime_error(output_.string() +
                               ": already exists; pass --overwrite or choose another folder");
    }
    const Status moved = base::ReplaceFolder(path_.string(), output_.string());
    if (!moved.ok()) throw std::runtime_error(moved.message());
    committed_ = true;
  }

 private:
  fs::path output_;
  fs::path path_;
  bool committed_ = false;
};

// Runs COLMAP steps with progress, timing and error reporting.
class ColmapSteps {
 public:
  ColmapSteps(std::string colmap, std::string log_path, int num_images,
              SparseStageResult* result)
      : colmap_(std::move(colmap)), log_path_(std::move(log_path)), num_images_(num_images),
        result_(result) {}

  // The error when the mapper registers nothing; empty: the generic one.
  std::string nothing_registered;

  void Run(const std::string& command, const std::vector<std::string>& args,
           const std::string& label) {
    util::Progress progress(label, 1000);
    auto on_line = [&](const std::string& line) {
      long done = 0, total = 0;
      if (ParseColmapProgress(line, num_images_, &done, &total)) {
        progress.Set(done * 1000 / total);
      }
    };
    const ColmapResult r = RunColmap(colmap_, command, args, log_path_, on_line);
    if (InterruptRequested()) throw std::runtime_error("interrupted during COLMAP " + command);
    if (r.signal == 0 && r.exit_code != 0 && command == "mapper" &&
        r.last_lines.find("failed to create sparse model") != std::string::npos) {
      throw std::runtime_error(nothing_registered.empty() ? NothingRegisteredMessage(num_images_)
                                                          : nothing_registered);
    }
    if (r.signal != 0 || r.exit_code != 0) {
      throw std::runtime_error("COLMAP " + command + " failed (" + DescribeExit(r) +
                               "): " + LastLines(r.last_lines) + " [full log kept next to the output]");
    }
    progress.Finish();
    Add(command, r.seconds);
  }

  void Add(const std::string& step, double seconds) {
    // Repeated steps (one feature_extractor per camera group) add up.
    for (auto& [name, s] : result_->timings_s) {
      if (name == step) {
        s += seconds;
        return;
      }
    }
    result_->timings_s.emplace_back(step, seconds);
  }

 private:
  std::string colmap_;
  std::string log_path_;
  int num_images_;
  SparseStageResult* result_;
};

void AppendLog(const std::string& log_path, const std::string& text) {
  std::ofstream log(log_path, std::ios::app);
  log << "# " << text << "\n";
}

double SecondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Matches the descriptors of the database's photos over the pairs that
// COLMAP's exhaustive (or sequential) matcher considers and stores them;
// that matcher, run next, skips the descriptor matching of every pair whose
// matches exist and only verifies them. Returns "N pairs, M matches".
std::string MatchIntoDatabase(const std::string& db, bool exhaustive, int sequential_overlap,
                              int num_threads) {
  std::vector<DatabaseImage> images = ReadDatabaseImages(db);
  std::vector<SiftDescriptors> descriptors;
  for (DatabaseImage& im : images) descriptors.push_back(std::move(im.descriptors));
  const int n = static_cast<int>(images.size());
  const std::vector<std::pair<int, int>> pairs =
      exhaustive ? ExhaustivePairs(n) : SequentialPairs(n, sequential_overlap);
  std::vector<FeatureMatches> matches;
  {
    util::Progress progress("matching", static_cast<int64_t>(pairs.size()));
    matches = MatchPairs(descriptors, pairs, DescriptorMatchOptions(), num_threads,
                         [&](int done, int) {
                           progress.Set(done);
                           return !InterruptRequested();
                         });
    if (InterruptRequested()) throw std::runtime_error("interrupted during matching");
    progress.Finish();
  }
  std::vector<std::pair<int64_t, int64_t>> id_pairs;
  size_t total = 0;
  for (size_t k = 0; k < pairs.size(); ++k) {
    id_pairs.emplace_back(images[pairs[k].first].image_id, images[pairs[k].second].image_id);
    total += matches[k].size();
  }
  WriteDatabaseMatches(db, id_pairs, matches);
  return std::to_string(pairs.size()) + " pairs, " + std::to_string(total) + " matches";
}

Json OptionsJson(const SparseStageOptions& o) {
  const char* matcher = o.matcher == MatcherType::kAuto         ? "auto"
                        : o.matcher == MatcherType::kExhaustive ? "exhaustive"
                                                                : "sequential";
  return {{"working_megapixels", o.import.working_megapixels},
          {"skip_unreadable", o.import.skip_unreadable},
          {"allow_mixed_devices", o.import.allow_mixed_devices},
          {"focal_px", o.import.focal_px},
          {"jpeg_quality", o.import.jpeg_quality},
          {"video",
           {{"max_frames", o.video.max_frames},
            {"min_step_fraction", o.video.min_step_fraction},
            {"blur_ratio", o.video.blur_ratio},
            {"blur_window", o.video.blur_window},
            {"analysis_long_side", o.video.analysis_long_side},
            {"focal_guess", o.video.focal_guess}}},
          {"camera_model", o.camera_model},
          {"shared_camera", o.shared_camera},
          {"matcher", matcher},
          {"exhaustive_max_photos", o.exhaustive_max_photos},
          {"sequential_overlap", o.sequential_overlap},
          {"max_features", o.max_features},
          {"sift_first_octave", o.sift_first_octave},
          {"native_matching", o.native_matching},
          {"num_threads", o.num_threads},
          {"init_min_tri_angle_deg", o.init_min_tri_angle_deg},
          {"min_registered_fraction", o.min_registered_fraction},
          {"min_photo_points", o.min_photo_points},
          {"depth_ranges",
           {{"near_percentile", o.depth_ranges.near_percentile},
            {"far_percentile", o.depth_ranges.far_percentile},
            {"near_margin", o.depth_ranges.near_margin},
            {"far_margin", o.depth_ranges.far_margin},
            {"min_points", o.depth_ranges.min_points},
            {"min_near_over_far", o.depth_ranges.min_near_over_far},
            {"frustum_near_points", o.depth_ranges.frustum_near_points}}},
          {"frame",
           {{"robust_centre", o.frame.robust_centre},
            {"min_partial_resultant", o.frame.min_partial_resultant}}}};
}

// Whether `input` is read as a COLMAP workspace (images/ and a model) rather
// than as photos; throws if a workspace is required and this is none.
bool IsWorkspace(const std::string& input, const std::string& video,
                 const std::vector<fs::path>& workspace_models, SparseInputType type) {
  const fs::path input_path(input);
  std::error_code ec;
  switch (type) {
    case SparseInputType::kAuto:
      return video.empty() && !workspace_models.empty() && fs::is_directory(input_path / "images", ec);
    case SparseInputType::kWorkspace:
      if (workspace_models.empty() || !fs::is_directory(input_path / "images", ec)) {
        throw std::runtime_error(input + ": not a COLMAP workspace (expected images/ and a model "
                                 "in sparse/ or sparse/0 with cameras, images and points3D files)");
      }
      return true;
    case SparseInputType::kPhotos:
      break;
  }
  return false;
}

// What the registration starts from: the photos' folder, the model's folder
// and the model, and the names of every input photo.
struct RawModel {
  fs::path image_dir;
  fs::path model_dir;
  geometry::SparseModel model;
  std::vector<std::string> all_names;
};

// A workspace's largest model, whose photos must all be in its images/.
RawModel WorkspaceModel(const fs::path& input_path, const std::vector<fs::path>& workspace_models,
                        const std::string& log_path) {
  std::error_code ec;
  RawModel raw;
  raw.image_dir = input_path / "images";
  auto [dir, model] = LargestModel(workspace_models);
  raw.model_dir = dir;
  raw.model = std::move(model);
  for (const auto& [id, image] : raw.model.images) {
    raw.all_names.push_back(image.name);
    if (!fs::exists(raw.image_dir / image.name, ec)) {
      throw std::runtime_error((raw.image_dir / image.name).string() +
                               ": missing; the workspace's model " + raw.model_dir.string() +
                               " lists it");
    }
  }
  AppendLog(log_path, "workspace model " + raw.model_dir.string());
  return raw;
}

// The factor of the long side that a video's frames take as their focal
// prior: VideoFrameOptions::focal_guess unless --focal-px gives one, 0 for
// photos and when no guess is asked for.
double VideoFocalGuess(const std::string& video, const SparseStageOptions& options) {
  return !video.empty() && !(options.import.focal_px > 0) ? options.video.focal_guess : 0.0;
}

// 1. The photos imported into WORK/images at the working resolution (a
// video's picked frames first), skipped files logged.
PhotoImport ImportInput(const std::string& input, const std::string& video,
                        const SparseStageOptions& options, const fs::path& work,
                        const std::string& log_path, SparseStageResult* result) {
  std::string photo_dir = input;
  if (!video.empty()) {
    const fs::path frames = work / "video_frames";
    fs::create_directories(frames);
    result->video = ExtractVideoFrames(video, frames.string(), options.video);
    const VideoFrames& v = result->video;
    char line[256];
    std::snprintf(line, sizeof(line),
                  "frame selection: %d frames of %dx%d at %.3g fps (rotation %d degrees), "
                  "%d blurred, motion %.2f frame diagonals; picked %zu in %.1f s",
                  v.frames_decoded, v.width, v.height, v.fps, v.rotation_deg, v.blurred,
                  v.motion_diagonals, v.picked.size(), v.seconds);
    AppendLog(log_path, line);
    util::LogInfo(line);
    result->timings_s.emplace_back("frame_selection", v.seconds);
    photo_dir = frames.string();
  }
  PhotoImportOptions import = options.import;
  if (const double guess = VideoFocalGuess(video, options); guess > 0) {
    const VideoFrames& v = result->video;
    import.focal_px = guess * std::max(v.width, v.height);
    const std::string line = "focal prior of the video's frames: " + FormatNumber(import.focal_px) +
                             " px, guessed (" + FormatNumber(guess) +
                             " times the long side, a phone's main camera); give --focal-px "
                             "if the camera's differs";
    AppendLog(log_path, line);
    util::LogInfo(line);
  }
  const auto t0 = std::chrono::steady_clock::now();
  PhotoImport photos;
  {
    util::Progress progress("import photos", 1000);
    photos = ImportPhotos(photo_dir, (work / "images").string(), import,
                          [&](int done, int total) {
                            if (InterruptRequested()) throw std::runtime_error("interrupted");
                            progress.Set(static_cast<int64_t>(done) * 1000 / std::max(total, 1));
                          });
  }
  result->skipped = photos.skipped;
  for (const auto& s : photos.skipped) {
    util::LogWarning("skipped " + s.file + ": " + s.reason);
    AppendLog(log_path, "skipped " + s.file + ": " + s.reason);
  }
  result->timings_s.emplace_back("import", SecondsSince(t0));
  return photos;
}

// COLMAP's extractor, matcher and mapper run on one thread. Each of its worker
// threads draws from its own random generator, seeded alike, so with more
// threads the RANSAC draws a task gets depend on scheduling and the model
// changes from run to run (a 16-photo capture registered 12 photos in 2 runs
// of 20); on one thread the same photos give the same model, byte for byte, at
// about 5 s more on fern (docs/DECISIONS.md, "A deterministic sparse stage").
constexpr const char* kColmapThreads = "1";

// 2. Features, one extractor run per camera group so each gets its own
// calibration and focal prior (TOOLCHAIN.md: resized photos lost their EXIF).
void ExtractFeatures(const PhotoImport& photos, const SparseStageOptions& options, const std::string& db,
                     const fs::path& image_dir, const fs::path& work, const std::string& log_path,
                     ColmapSteps* steps) {
  for (size_t g = 0; g < photos.groups.size(); ++g) {
    const CameraGroup& group = photos.groups[g];
    const fs::path list = work / ("group" + std::to_string(g) + ".txt");
    {
      std::ofstream out(list);
      for (int i : group.photos) out << photos.photos[i].name << "\n";
      if (!out) throw std::runtime_error(list.string() + ": cannot write (disk full?)");
    }
    std::vector<std::string> args = {
        "--database_path", db, "--image_path", image_dir.string(), "--image_list_path",
        list.string(), "--ImageReader.camera_model", options.camera_model,
        "--ImageReader.single_camera", options.shared_camera ? "1" : "0",
        "--SiftExtraction.use_gpu", "0", "--SiftExtraction.num_threads", kColmapThreads,
        "--SiftExtraction.max_num_features", std::to_string(options.max_features),
        "--SiftExtraction.first_octave", std::to_string(options.sift_first_octave)};
    if (group.focal_px > 0) {
      args.push_back("--ImageReader.camera_params");
      args.push_back(CameraParams(options.camera_model, group.focal_px, group.width, group.height));
    }
    AppendLog(log_path, "camera group " + std::to_string(g) + ": " + group.device + ", " +
                            std::to_string(group.width) + "x" + std::to_string(group.height) +
                            ", focal prior " +
                            (group.focal_px > 0 ? FormatNumber(group.focal_px) + " px" : "none"));
    steps->Run("feature_extractor", args, "features");
  }
}

// 3. Matching: casual3d's descriptor matching (native_matching), then
// COLMAP's matcher, which verifies the stored matches.
void MatchFeatures(int n, const SparseStageOptions& options, const std::string& db,
                   const std::string& log_path, ColmapSteps* steps, SparseStageResult* result) {
  const bool exhaustive =
      options.matcher == MatcherType::kExhaustive ||
      (options.matcher == MatcherType::kAuto && n <= options.exhaustive_max_photos);
  result->matcher = exhaustive ? "exhaustive" : "sequential";
  if (options.native_matching) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::string summary =
        MatchIntoDatabase(db, exhaustive, options.sequential_overlap, options.num_threads);
    const double seconds = SecondsSince(t0);
    char took[32];
    std::snprintf(took, sizeof(took), " in %.1f s", seconds);
    AppendLog(log_path, "descriptor matching: " + summary + took);
    steps->Add("descriptor_matching", seconds);
  }
  std::vector<std::string> match_args = {"--database_path", db, "--SiftMatching.use_gpu", "0",
                                         "--SiftMatching.num_threads", kColmapThreads};
  if (!exhaustive) {
    match_args.insert(match_args.end(),
                      {"--SequentialMatching.overlap", std::to_string(options.sequential_overlap),
                       "--SequentialMatching.loop_detection", "0"});
  }
  steps->Run(exhaustive ? "exhaustive_matcher" : "sequential_matcher", match_args, "matching");
}

// Steps 1 to 4 on photos: import, features, matching, then the mapper; the
// largest model it makes.
RawModel RegisterPhotos(const std::string& input, const std::string& video,
                        const SparseStageOptions& options, const std::string& colmap,
                        const fs::path& work, const std::string& log_path,
                        SparseStageResult* result) {
  std::error_code ec;
  const PhotoImport photos = ImportInput(input, video, options, work, log_path, result);
  RawModel raw;
  for (const auto& p : photos.photos) raw.all_names.push_back(p.name);
  raw.image_dir = work / "images";
  const int n = static_cast<int>(photos.photos.size());
  ColmapSteps steps(colmap, log_path, n, result);
  const bool focal_unknown = std::any_of(photos.groups.begin(), photos.groups.end(),
                                         [](const CameraGroup& g) { return !(g.focal_px > 0); });
  steps.nothing_registered = NothingRegisteredMessage(n, result->input_type, focal_unknown,
                                                      VideoFocalGuess(video, options));
  const std::string db = (work / "database.db").string();
  ExtractFeatures(photos, options, db, raw.image_dir, work, log_path, &steps);
  MatchFeatures(n, options, db, log_path, &steps, result);

  // 4. Mapping; keep the largest model.
  const fs::path mapped = work / "sparse";
  fs::create_directories(mapped);
  steps.Run("mapper",
            {"--database_path", db, "--image_path", raw.image_dir.string(), "--output_path",
             mapped.string(), "--Mapper.num_threads", kColmapThreads, "--Mapper.init_min_tri_angle",
             FormatNumber(options.init_min_tri_angle_deg)},
            "mapping");
  std::vector<fs::path> models;
  for (const auto& entry : fs::directory_iterator(mapped, ec)) {
    if (entry.is_directory() && HasModelFiles(entry.path())) models.push_back(entry.path());
  }
  std::sort(models.begin(), models.end());
  if (models.empty()) throw std::runtime_error(steps.nothing_registered);
  auto [dir, model] = LargestModel(models);
  raw.model_dir = dir;
  raw.model = std::move(model);
  if (models.size() > 1) {
    AppendLog(log_path, std::to_string(models.size()) + " models; kept " + raw.model_dir.string());
  }
  return raw;
}

// Leaves out of `raw`'s model the photos that see fewer than
// options.min_photo_points 3D points (untied_photos.h), writing the model
// that remains to WORK/sparse_tied for the undistortion.
void LeaveOutUntiedPhotos(const SparseStageOptions& options, const fs::path& work,
                          const std::string& log_path, RawModel* raw) {
  const std::vector<UntiedPhoto> dropped = DropUntiedPhotos(options.min_photo_points, &raw->model);
  for (const UntiedPhoto& u : dropped) {
    const std::string line = "left out " + u.name + ": registered, but sees only " +
                             std::to_string(u.points) + " 3D points (fewer than " +
                             std::to_string(options.min_photo_points) +
                             "): nothing ties its pose to the other photos";
    AppendLog(log_path, line);
    util::LogWarning(line);
  }
  if (dropped.empty()) return;
  raw->model_dir = work / "sparse_tied";
  fs::create_directories(raw->model_dir);
  geometry::WriteModelBinary(raw->model, raw->model_dir.string());
}

// Registration check: which photos the model holds; throws if fewer than
// min_registered_fraction of them (and at least 3).
void CheckRegistration(const RawModel& raw, const SparseStageOptions& options, SparseStageResult* result) {
  std::set<std::string> registered;
  for (const auto& [id, image] : raw.model.images) registered.insert(image.name);
  result->num_photos = static_cast<int>(raw.all_names.size());
  result->num_registered = static_cast<int>(registered.size());
  for (const auto& name : raw.all_names) {
    if (!registered.count(name)) result->unregistered.push_back(name);
  }
  const int needed = std::max(
      3, static_cast<int>(std::ceil(options.min_registered_fraction * result->num_photos - 1e-9)));
  if (result->num_registered < needed) {
    throw std::runtime_error(
        "COLMAP registered only " + std::to_string(result->num_registered) + " of " +
        std::to_string(result->num_photos) + " photos (need " + std::to_string(needed) +
        "); not registered: " + JoinNames(result->unregistered, 8) +
        ". Retake with more overlap between neighbouring photos and a more textured scene");
  }
  if (!result->unregistered.empty()) {
    util::LogWarning("COLMAP registered " + std::to_string(result->num_registered) + " of " +
                     std::to_string(result->num_photos) +
                     " photos; left out: " + JoinNames(result->unregistered, 8));
  }
}

// 5. Undistortion into PINHOLE cameras: TMP/images and TMP/sparse (binary
// and text).
void Undistort(const RawModel& raw, const std::string& colmap, const std::string& log_path,
               const fs::path& tmp, const fs::path& work, SparseStageResult* result) {
  ColmapSteps steps(colmap, log_path, result->num_registered, result);
  const fs::path undistorted = work / "undistorted";
  steps.Run("image_undistorter",
            {"--image_path", raw.image_dir.string(), "--input_path", raw.model_dir.string(),
             "--output_path", undistorted.string(), "--output_type", "COLMAP"},
            "undistorting");
  fs::rename(undistorted / "images", tmp / "images");
  fs::create_directories(tmp / "sparse");
  for (const char* f : {"cameras.bin", "images.bin", "points3D.bin"}) {
    fs::rename(undistorted / "sparse" / f, tmp / "sparse" / f);
  }
  steps.Run("model_converter",
            {"--input_path", (tmp / "sparse").string(), "--output_path", (tmp / "sparse").string(),
             "--output_type", "TXT"},
            "writing model");
}

// 6. Scene set-up: the model's points, the panorama frame and the depth
// ranges (TMP/frame.json, TMP/depth_ranges.json).
void SetUpScene(const fs::path& tmp, const SparseStageOptions& options, SparseStageResult* result) {
  const auto t_setup = std::chrono::steady_clock::now();
  const geometry::SparseModel model = geometry::ReadModel((tmp / "sparse").string());
  result->num_points = static_cast<int>(model.points.size());
  double error_sum = 0;
  for (const auto& [id, p] : model.points) error_sum += p.error;
  result->mean_reprojection_error_px = model.points.empty() ? 0.0 : error_sum / model.points.size();
  const PanoramaFrame frame = ComputePanoramaFrame(model, options.frame, &result->frame);
  WritePanoramaFrame(frame, (tmp / "frame.json").string(), &result->frame);
  WriteDepthRanges(ComputeDepthRanges(model, options.depth_ranges),
                   (tmp / "depth_ranges.json").string());
  result->timings_s.emplace_back("scene_setup", SecondsSince(t_setup));
}

// stage.json: what the stage did, with its options and timings.
Json StageJson(const fs::path& input_path, const std::string& colmap, const std::string& video,
               const SparseStageOptions& options, const SparseStageResult& result) {
  Json stage_video;
  Json skipped = Json::array();
  for (const SkippedPhoto& s : result.skipped) skipped.push_back({{"file", s.file}, {"reason", s.reason}});
  Json timings = Json::object();
  for (const auto& [step, s] : result.timings_s) timings[step] = s;
  if (!video.empty()) {
    const VideoFrames& v = result.video;
    stage_video = {{"file", v.video}, {"frames", v.frames_decoded}, {"fps", v.fps},
                   {"width", v.width}, {"height", v.height}, {"rotation_deg", v.rotation_deg},
                   {"blurred", v.blurred}, {"motion_diagonals", v.motion_diagonals},
                   {"picked", v.picked}, {"seconds", v.seconds}};
  }
  Json stage = {{"format", "casual3d-stage-sparse"},
                {"version", "1.0"},
                {"input", fs::absolute(input_path).lexically_normal().string()},
                {"input_type", result.input_type},
                {"colmap", colmap},
                {"options", OptionsJson(options)},
                {"matcher", result.matcher},
                {"num_photos", result.num_photos},
                {"num_registered", result.num_registered},
                {"unregistered", result.unregistered},
                {"skipped", skipped},
                {"num_points", result.num_points},
                {"mean_reprojection_error_px", result.mean_reprojection_error_px},
                {"timings_s", timings}};
  if (!stage_video.is_null()) stage["video"] = stage_video;
  return stage;
}

}  // namespace

SparseStageResult RunSparseStage(const std::string& input, const std::string& output,
                                 const SparseStageOptions& options) {
  const Status status = options.Check();
  if (!status.ok()) throw std::invalid_argument("sparse stage options: " + status.message());
  const auto stage_start = std::chrono::steady_clock::now();

  // Inputs first: cheap checks before any work.
  const fs::path input_path(input);
  std::error_code ec;
  const std::string video =
      options.input_type == SparseInputType::kWorkspace ? "" : VideoOf(input);
  if (!fs::is_directory(input_path, ec) && video.empty()) {
    throw std::runtime_error(input + ": not a folder or a video; give a folder of photos, a video "
                             "clip (.mp4, .mov) or a COLMAP workspace (images/ and sparse/)");
  }
  const fs::path output_path = fs::absolute(fs::path(output)).lexically_normal();
  if (fs::exists(output_path, ec) && !options.overwrite) {
    throw std::runtime_error(output + ": already exists; pass --overwrite or choose another folder");
  }
  const std::vector<fs::path> workspace_models = WorkspaceModels(input_path);
  const bool workspace = IsWorkspace(input, video, workspace_models, options.input_type);
  const std::string colmap = FindColmap(options.colmap_path);

  ScopedInterruptHandler interrupt_handler;
  StagingDir staging(output_path);
  const fs::path tmp = staging.path();
  const fs::path work = tmp / "work";
  fs::create_directories(work / "images");
  const std::string log_path = (tmp / "sparse_log.txt").string();
  AppendLog(log_path, "casual3d sparse: input " + input + ", output " + output);

  SparseStageResult result;
  result.input_type = workspace ? "workspace" : video.empty() ? "photos" : "video";
  RawModel raw = workspace ? WorkspaceModel(input_path, workspace_models, log_path)
                                 : RegisterPhotos(input, video, options, colmap, work, log_path, &result);
  if (!workspace && options.min_photo_points > 0) LeaveOutUntiedPhotos(options, work, log_path, &raw);
  CheckRegistration(raw, options, &result);
  Undistort(raw, colmap, log_path, tmp, work, &result);
  SetUpScene(tmp, options, &result);

  if (!options.keep_work) {
    fs::remove_all(work, ec);
  }
  result.timings_s.emplace_back("total", SecondsSince(stage_start));
  io::WriteFileAtomic((tmp / "stage.json").string(),
                      StageJson(input_path, colmap, video, options, result).dump(2) + "\n");
  AppendLog(log_path, "done: " + std::to_string(result.num_registered) + "/" +
                          std::to_string(result.num_photos) + " registered, " +
                          std::to_string(result.num_points) + " points");
  if (InterruptRequested()) throw std::runtime_error("interrupted");
  staging.Commit(options.overwrite);
  return result;
}

}  // namespace casual3d::sfm
