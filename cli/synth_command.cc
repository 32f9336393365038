// `casual3d synth`: writes a synthetic capture folder with ground truth
// (reconstruct/synth/synth.h; layout in spec/capture-folder.md).

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "cli/command.h"
#include "cli/described_option.h"
#include "reconstruct/synth/synth.h"

namespace casual3d::cli {

void AddSynthCommand(CLI::App& app) {
  auto options = std::make_shared<synth::SynthOptions>();
  auto rig_name = std::make_shared<std::string>("partial");
  auto out_dir = std::make_shared<std::string>("capture");
  CLI::App* cmd = app.add_subcommand(
      "synth", "Render a synthetic capture (photos, COLMAP model, depth, ground-truth panorama)");
  cmd->add_option("--rig", *rig_name, "Capture rig: partial (phone, 4x4 grid), sphere (DSLR, 2 rings) or walk-around (12 photos "
                 "on a 90-degree arc around a subject 1.3 m ahead: a capture 3D photos are not made from)")
      ->capture_default_str();
  cmd->add_option("-o,--output", *out_dir, "Capture folder to write")->capture_default_str();
  AddDescribedOption(cmd, "--width", *options, options->width);
  AddDescribedOption(cmd, "--height", *options, options->height);
  AddDescribedOption(cmd, "--photos", *options, options->num_photos);
  AddDescribedOption(cmd, "--noise", *options, options->noise_sigma);
  AddDescribedOption(cmd, "--exposure-jitter", *options, options->exposure_jitter_stops);
  cmd->add_flag("--moving-object", options->moving_object,
                "Move the blue ball by 1 cm between photos");
  AddDescribedOption(cmd, "--seed", *options, options->seed);
  AddDescribedOption(cmd, "--panorama-width", *options, options->panorama_width)
      ->check(CLI::Validator(
          [](std::string& text) {
            if (std::atoi(text.c_str()) % 2 == 0) return std::string();
            return text + " is odd; it must be even (height = width / 2)";
          },
          "", "even"));
  AddDescribedOption(cmd, "--jpeg-quality", *options, options->jpeg_quality);
  AddDescribedOption(cmd, "--video-frames", *options, options->video_frames);
  AddDescribedOption(cmd, "--threads", *options, options->num_threads);
  cmd->callback([options, rig_name, out_dir] {
    if (!synth::RigKindFromName(*rig_name, &options->rig)) {
      throw std::invalid_argument("--rig '" + *rig_name + "' is not partial, sphere or walk-around");
    }
    if (const Status st = options->Check(); !st.ok()) throw std::invalid_argument(st.message());
    const synth::CaptureSummary s = synth::GenerateCapture(*options, *out_dir);
    std::printf(
        "synth: wrote %s: %d photos of %dx%d (%s rig), %zu points (mean track %.1f), "
        "depth %.2f-%.1f m, panorama %dx%d%s; photos %.1f s, panorama %.1f s, total %.1f s\n",
        out_dir->c_str(), s.num_photos, s.width, s.height, rig_name->c_str(), s.num_points,
        s.mean_track_length, s.depth_min_m, s.depth_max_m, s.panorama_width, s.panorama_height,
        s.wrote_master ? " + master.exr" : "", s.seconds_photos, s.seconds_panorama,
        s.seconds_total);
    if (s.video_frames > 0) {
      std::printf(
          "synth: wrote %s/video: %d frames and their ground truth (video/sparse), the nearest "
          "frame %.1f-%.1f cm from each photo; %.1f s\n",
          out_dir->c_str(), s.video_frames, 100.0 * s.video_min_distance_m,
          100.0 * s.video_max_distance_m, s.seconds_video);
    }
  });
}

}  // namespace casual3d::cli
