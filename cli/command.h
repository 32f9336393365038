#pragma once

// Each subcommand lives in its own cli/<name>_command.cc and registers itself
// with main() through an Add*Command function declared here. Commands parse
// options, check them and call the library; they report failure by throwing
// (std::exception), which main() turns into one line on stderr and exit code 1.

#include <CLI/CLI.hpp>

namespace casual3d::sfm {
struct SparseStageOptions;
}

namespace casual3d::cli {

// Options every command understands (set by main before the command runs).
struct GlobalOptions {
  bool verbose = false;  // --verbose: more detail on stderr.
  bool json = false;     // --json: machine-readable log lines (JSON) on stderr.
};
const GlobalOptions& Globals();

// `casual3d view <package> [--port N]` (cli/view_command.cc).
void AddViewCommand(CLI::App& app);

// `casual3d sparse <photos-or-workspace> -o <out>` (cli/sparse_command.cc).
void AddSparseCommand(CLI::App& app);

// --max-features, --sift-first-octave and --colmap-matching, shared by
// `sparse` and `reconstruct` (cli/sparse_command.cc).
void AddSiftOptions(CLI::App* cmd, sfm::SparseStageOptions* options);
// --strict-photos, --mixed-cameras, --max-frames and --video-focal-guess
// (photo and video input).
void AddPhotoInputOptions(CLI::App* cmd, sfm::SparseStageOptions* options);

// `casual3d dense <workspace> -o <out>` (cli/dense_command.cc).
void AddDenseCommand(CLI::App& app);

// `casual3d synth [--rig partial|sphere] [-o DIR] ...` (cli/synth_command.cc).
void AddSynthCommand(CLI::App& app);

// `casual3d panorama <workspace> -o <out>` (cli/panorama_command.cc).
void AddPanoramaCommand(CLI::App& app);

// `casual3d reconstruct <photos> -o <out>` (cli/reconstruct_command.cc).
void AddReconstructCommand(CLI::App& app);

// `casual3d encode <master.exr> -o <package>` (cli/encode_command.cc).
void AddEncodeCommand(CLI::App& app);

// `casual3d info <package>` (cli/info_command.cc).
void AddInfoCommand(CLI::App& app);

// `casual3d validate <package>` (cli/validate_command.cc).
void AddValidateCommand(CLI::App& app);

// `casual3d export <package> --glb out.glb [--draco]` (cli/export_command.cc).
void AddExportCommand(CLI::App& app);

// `casual3d evaluate <capture> <3d-photo>... [-o report.html]` (cli/evaluate_command.cc).
void AddEvaluateCommand(CLI::App& app);

}  // namespace casual3d::cli
