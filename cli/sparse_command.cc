// `casual3d sparse <photos-or-colmap-workspace> -o <out> [options]`: the sparse
// stage (reconstruct/sfm/sparse_stage.h). Parses options, runs the stage and
// prints a short summary; the stage's output layout is spec/stage-sparse.md.

#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "cli/command.h"
#include "cli/described_option.h"
#include "reconstruct/sfm/sparse_stage.h"
#include "reconstruct/util/log.h"

namespace casual3d::cli {
namespace {

struct SparseCommandOptions {
  std::string input;
  std::string output;
  std::string input_type = "auto";
  std::string matcher = "auto";
  bool camera_per_photo = false;
  sfm::SparseStageOptions stage;
};

void RunSparse(SparseCommandOptions options) {
  static const std::map<std::string, sfm::SparseInputType> kInputTypes = {
      {"auto", sfm::SparseInputType::kAuto},
      {"photos", sfm::SparseInputType::kPhotos},
      {"workspace", sfm::SparseInputType::kWorkspace}};
  static const std::map<std::string, sfm::MatcherType> kMatchers = {
      {"auto", sfm::MatcherType::kAuto},
      {"exhaustive", sfm::MatcherType::kExhaustive},
      {"sequential", sfm::MatcherType::kSequential}};
  options.stage.input_type = kInputTypes.at(options.input_type);
  options.stage.matcher = kMatchers.at(options.matcher);
  options.stage.shared_camera = !options.camera_per_photo;
  const Status status = options.stage.Check();
  if (!status.ok()) throw std::invalid_argument(status.message());

  const sfm::SparseStageResult r = sfm::RunSparseStage(options.input, options.output, options.stage);
  std::string timings;
  for (const auto& [step, s] : r.timings_s) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%s%s %.1f s", timings.empty() ? "" : ", ", step.c_str(), s);
    timings += buf;
  }
  std::printf("%s: %d of %d photos registered, %d points, %.2f px mean reprojection error\n",
              options.output.c_str(), r.num_registered, r.num_photos, r.num_points,
              r.mean_reprojection_error_px);
  std::printf("frame: %s capture, rig radius %.3g; timings: %s\n",
              r.frame.full_capture ? "full 360-degree" : "partial", r.frame.rig_radius,
              timings.c_str());
}

}  // namespace

void AddSiftOptions(CLI::App* cmd, sfm::SparseStageOptions* options) {
  AddDescribedOption(cmd, "--max-features", *options, options->max_features);
  AddDescribedOption(cmd, "--sift-first-octave", *options, options->sift_first_octave);
  cmd->add_flag_callback("--colmap-matching", [options] { options->native_matching = false; },
                         "Match descriptors with COLMAP's own CPU matcher (same criteria, slower)");
}

void AddPhotoInputOptions(CLI::App* cmd, sfm::SparseStageOptions* options) {
  cmd->add_flag_callback("--strict-photos", [options] { options->import.skip_unreadable = false; },
                         "Stop at an unreadable, truncated or corrupt photo instead of skipping it");
  cmd->add_flag("--mixed-cameras", options->import.allow_mixed_devices,
                "Accept photos from different cameras (one calibration per camera)");
  AddDescribedOption(cmd, "--max-frames", *options, options->video.max_frames);
  AddDescribedOption(cmd, "--video-focal-guess", *options, options->video.focal_guess);
}

void AddSparseCommand(CLI::App& app) {
  auto options = std::make_shared<SparseCommandOptions>();
  sfm::SparseStageOptions& s = options->stage;
  CLI::App* cmd = app.add_subcommand(
      "sparse",
      "Calibrate the cameras of a folder of photos (or an existing COLMAP workspace) with COLMAP "
      "and write undistorted photos, the sparse model, the 3D photo's frame and depth ranges");
  cmd->add_option("input", options->input,
                  "Folder of photos (JPEG, PNG, TIFF, HEIC), a video clip (or a folder holding "
                  "one), or a COLMAP workspace")
      ->required();
  cmd->add_option("-o,--output", options->output, "Output folder (must not exist)")->required();
  cmd->add_option("--input-type", options->input_type, "auto, photos or workspace")
      ->check(CLI::IsMember({"auto", "photos", "workspace"}))
      ->capture_default_str();
  AddDescribedOption(cmd, "--working-megapixels", s, s.import.working_megapixels);
  AddDescribedOption(cmd, "--focal-px", s, s.import.focal_px);
  AddPhotoInputOptions(cmd, &s);
  AddDescribedOption(cmd, "--camera-model", s, s.camera_model);
  cmd->add_flag("--camera-per-photo", options->camera_per_photo,
                "Calibrate every photo separately (zooming or unknown cameras)");
  cmd->add_option("--matcher", options->matcher, "auto, exhaustive or sequential")
      ->check(CLI::IsMember({"auto", "exhaustive", "sequential"}))
      ->capture_default_str();
  AddSiftOptions(cmd, &s);
  AddDescribedOption(cmd, "--threads", s, s.num_threads);
  AddDescribedOption(cmd, "--init-tri-angle", s, s.init_min_tri_angle_deg);
  AddDescribedOption(cmd, "--min-registered", s, s.min_registered_fraction);
  AddDescribedOption(cmd, "--min-photo-points", s, s.min_photo_points);
  cmd->add_flag("--robust-centre", s.frame.robust_centre,
                "Centre the 3D photo at the geometric median of the cameras, not their mean");
  AddDescribedOption(cmd, "--colmap", s, s.colmap_path);
  cmd->add_flag("--overwrite", s.overwrite, "Replace an existing output folder when done");
  cmd->add_flag("--keep-work", s.keep_work, "Keep COLMAP's database and raw models in OUT/work");
  cmd->callback([options] { RunSparse(*options); });
}

}  // namespace casual3d::cli
